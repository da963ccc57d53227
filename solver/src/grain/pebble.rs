//! Seeded convex "pebble" meshes for users without grain scans: the convex hull of a point
//! cloud on a lumpy ellipsoid, chipped by random planes so that the grain has the flat facets
//! and edges of fluvial gravel rather than the smoothness of an ellipsoid, as angular at its
//! form as the shipped Rhine scans.

use nalgebra::Vector3;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::form_distribution::RHINE_FORMS;
use super::mesh::TriMesh;
use super::simplify::{SimplifyError, simplify};

/// One pebble: the hull of a cloud dense enough for more than `max_faces` triangles, simplified
/// to `max_faces` like a scan (§5.2.1). A hull of just (max_faces + 4)/2 points, the most that
/// keep within the bound unsimplified, loses the points chipped into a facet's interior and
/// ends at 170–240 of 300 faces, and Table 4 has coarser meshes pack looser (~0.005 between
/// ≤ 300 faces and the next coarser column).
pub fn pebble(seed: u64, max_faces: usize) -> Result<TriMesh, SimplifyError> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let points = 2 * (max_faces.max(8) + 4);
    // Pebbles get the realistic own forms of the Rhine gravel (Table 2, Fig. 2).
    let forms = RHINE_FORMS.sampler().expect("Table 2's distribution lies in the admissible ranges");
    let (fl, el) = forms.sample_flatness_elongation(&mut rng);
    let semi_axes = Vector3::new(1.0, el, el * fl);

    // Smooth lumps: a few broad bumps and dents of the radius.
    let lumps: Vec<(Vector3<f64>, f64)> =
        (0..6).map(|_| (random_direction(&mut rng), rng.random_range(-0.12..0.12))).collect();
    // Chips: planes that cut off caps, leaving flat facets; offsets as fractions of the support.
    // This many, this deep, make pebbles as angular as the Rhine scans (their sphericity over
    // that of the ellipsoid of their form, `Angularity`: 0.945 ± 0.008 for the 20 of
    // builtin:pebbles against 0.938 and 0.954 for the two scans; 4–8 chips at 0.72–0.92 gave
    // 0.968 ± 0.005, grains rounder than the scans at the same form; the denser cloud sharpens
    // the chips' edges, so they cut less deep than the 0.62–0.86 of a cloud of 152 points).
    let chips: Vec<(Vector3<f64>, f64)> =
        (0..rng.random_range(8..14)).map(|_| (random_direction(&mut rng), rng.random_range(0.66..0.88))).collect();

    let cloud: Vec<Vector3<f64>> = (0..points)
        .map(|_| {
            let u = random_direction(&mut rng);
            let lump: f64 = lumps.iter().map(|(c, a)| a * (4.0 * (u.dot(c) - 1.0)).exp()).sum();
            let mut p = (1.0 + lump + rng.random_range(-0.02..0.02)) * u.component_mul(&semi_axes);
            for (n, offset) in &chips {
                let support = n.component_mul(&semi_axes).norm();
                let excess = p.dot(n) - offset * support;
                if excess > 0.0 {
                    p -= excess * n;
                }
            }
            // A tiny jitter keeps chipped points off exact coplanarity, which quickhull dislikes.
            p + 1e-5 * random_direction(&mut rng)
        })
        .collect();
    let hull = TriMesh::convex_hull(&cloud).map_err(SimplifyError::Defect)?;
    Ok(simplify(&hull, max_faces.max(4))?.mesh)
}

/// `count` pebbles from one seed: pebble k uses seed·1,000,003 + k.
pub fn pebble_library(count: usize, seed: u64, max_faces: usize) -> Result<Vec<TriMesh>, SimplifyError> {
    (0..count as u64).map(|k| pebble(seed.wrapping_mul(1_000_003).wrapping_add(k), max_faces)).collect()
}

fn random_direction(rng: &mut ChaCha8Rng) -> Vector3<f64> {
    loop {
        let v = Vector3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        let n = v.norm();
        if n > 1e-3 && n <= 1.0 {
            return v / n;
        }
    }
}
