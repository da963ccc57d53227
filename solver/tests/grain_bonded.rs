//! Bonded-sphere grains of the second paper (Sun & Xiao, §2.4, Appendix, §3): Zingg classes,
//! hand-worked constructions, rigid-body mass properties and the a-priori comparison with the
//! ellipsoid of the same axes (its Figs. 4 and 5).

use std::collections::BTreeMap;
use std::f64::consts::PI;

use nalgebra::{Matrix3, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use solver::dem::Shape;
use solver::grain::{
    BondedGrain, ComponentSphere, EQUANT_EPSILON, FormParameters, ZinggClass, bonded_grain, construction,
    ellipsoid_mass,
};

fn form(l: f64, i: f64, s: f64) -> FormParameters {
    FormParameters::new(l, i, s).unwrap()
}

/// Relative closeness for quantities computed two ways in floating point: a few ulps of the
/// largest term involved, 1e-12 leaves room for sums of up to a few hundred terms.
fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-12 * scale
}

/// The a-priori sampling: D_l uniform in 0.2–2 mm (§3, after Smith and Cheung 2003); the paper
/// draws D_i/D_l and D_s/D_i "randomly" without a law, so both are uniform in 0.3–1 (DESIGN.md).
fn random_form(rng: &mut ChaCha8Rng) -> FormParameters {
    let l = rng.random_range(0.2e-3..2e-3);
    let i = l * rng.random_range(0.3..1.0);
    form(l, i, i * rng.random_range(0.3..1.0))
}

fn random_grains(count: usize, seed: u64) -> Vec<BondedGrain> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..count).map(|_| bonded_grain(&random_form(&mut rng)).unwrap()).collect()
}

/// Axis-aligned extents of a set of spheres.
fn extents(spheres: &[ComponentSphere]) -> Vector3<f64> {
    let lo = spheres.iter().fold(Vector3::repeat(f64::INFINITY), |m, c| m.inf(&c.center.add_scalar(-c.radius)));
    let hi = spheres.iter().fold(Vector3::repeat(f64::NEG_INFINITY), |m, c| m.sup(&c.center.add_scalar(c.radius)));
    hi - lo
}

/// Sorted radii and sorted pairwise centre distances: what a layout is up to a rigid motion.
fn shape_signature(spheres: &[ComponentSphere]) -> (Vec<f64>, Vec<f64>) {
    let mut radii: Vec<f64> = spheres.iter().map(|c| c.radius).collect();
    let mut distances = Vec::new();
    for (k, a) in spheres.iter().enumerate() {
        for b in &spheres[k + 1..] {
            distances.push((a.center - b.center).norm());
        }
    }
    radii.sort_by(f64::total_cmp);
    distances.sort_by(f64::total_cmp);
    (radii, distances)
}

fn assert_signature(spheres: &[ComponentSphere], radii: &[f64], distances: &[f64], scale: f64) {
    let (mut want_r, mut want_d) = (radii.to_vec(), distances.to_vec());
    want_r.sort_by(f64::total_cmp);
    want_d.sort_by(f64::total_cmp);
    let (got_r, got_d) = shape_signature(spheres);
    assert_eq!(got_r.len(), want_r.len(), "sphere count");
    for (g, w) in got_r.iter().zip(&want_r).chain(got_d.iter().zip(&want_d)) {
        assert!(close(*g, *w, scale), "{got_r:?} {got_d:?} vs {want_r:?} {want_d:?}");
    }
}

#[test]
fn zingg_classes_on_both_sides_of_each_threshold() {
    let d = 1e-6;
    let cases = [
        // D_i/D_l around 2/3 with D_s/D_i = 1/6 (disk | blade); a tie is "much shorter" (blade).
        ((9.0, 6.0 + d, 1.0), ZinggClass::Disk),
        ((9.0, 6.0, 1.0), ZinggClass::Blade),
        ((9.0, 6.0 - d, 1.0), ZinggClass::Blade),
        // D_s/D_i around 2/3 with D_i/D_l = 1/3 (rod | blade).
        ((9.0, 3.0, 2.0 + d), ZinggClass::Rod),
        ((9.0, 3.0, 2.0), ZinggClass::Blade),
        ((9.0, 3.0, 2.0 - d), ZinggClass::Blade),
        // D_s/D_i around 2/3 with D_i/D_l = 0.8 (equant | disk).
        ((10.0, 8.0, 16.0 / 3.0 + d), ZinggClass::Equant(4)),
        ((10.0, 8.0, 16.0 / 3.0 - d), ZinggClass::Disk),
        // D_i/D_l around 2/3 with D_s/D_i = 0.8 (equant | rod).
        ((9.0, 6.0 + d, 4.8), ZinggClass::Equant(4)),
        ((9.0, 6.0, 4.8), ZinggClass::Rod),
        // Inside equant: D_i/D_l around 1 − ε = 0.9 with D_s/D_i = 0.95 (subtype 1 | 2); a tie
        // is "not almost equal".
        ((10.0, 9.0 + d, 8.6), ZinggClass::Equant(1)),
        ((10.0, 9.0, 8.55), ZinggClass::Equant(2)),
        ((10.0, 9.0 - d, 8.55), ZinggClass::Equant(2)),
        // D_s/D_i around 0.9 with D_i/D_l = 0.95 (subtype 1 | 3).
        ((10.0, 9.5, 8.55 + d), ZinggClass::Equant(1)),
        ((10.0, 9.5, 8.55 - d), ZinggClass::Equant(3)),
        // D_s/D_i around 0.9 with D_i/D_l = 0.8 (subtype 2 | 4).
        ((10.0, 8.0, 7.2 + d), ZinggClass::Equant(2)),
        ((10.0, 8.0, 7.2 - d), ZinggClass::Equant(4)),
        // D_i/D_l around 0.9 with D_s/D_i = 0.8 (subtype 3 | 4).
        ((10.0, 9.0 + d, 7.2), ZinggClass::Equant(3)),
        ((10.0, 9.0 - d, 7.2), ZinggClass::Equant(4)),
        // Degenerate but valid: all axes equal, and I = L.
        ((1.0, 1.0, 1.0), ZinggClass::Equant(1)),
        ((1.0, 1.0, 0.5), ZinggClass::Disk),
    ];
    assert_eq!(EQUANT_EPSILON, 0.1);
    for ((l, i, s), want) in cases {
        assert_eq!(ZinggClass::of(&form(l, i, s)), want, "L = {l}, I = {i}, S = {s}");
    }
}

#[test]
fn class_names_and_their_json() {
    let names: Vec<&str> = ZinggClass::ALL.iter().map(|c| c.name()).collect();
    assert_eq!(names, ["disk", "blade", "rod", "equant-1", "equant-2", "equant-3", "equant-4"]);
    for class in ZinggClass::ALL {
        let json = serde_json::to_string(&class).unwrap();
        assert_eq!(json, format!("\"{}\"", class.name()));
        assert_eq!(serde_json::from_str::<ZinggClass>(&json).unwrap(), class);
    }
    assert!(serde_json::from_str::<ZinggClass>("\"equant-5\"").is_err());
}

#[test]
fn invalid_axes_are_refused() {
    let unordered = FormParameters { l: 1.0, i: 2.0, s: 0.5 };
    assert!(bonded_grain(&unordered).is_err());
    let zero = FormParameters { l: 1.0, i: 0.5, s: 0.0 };
    assert!(bonded_grain(&zero).is_err());
    assert!(construction(&zero).is_err());
}

#[test]
fn rod_is_a_row_of_touching_spheres_of_diameter_sqrt_si() {
    // (3, 1, 1): d_p = 1, n_l = 3; centres −1, 0, 1 on the long axis.
    let g = bonded_grain(&form(3.0, 1.0, 1.0)).unwrap();
    assert_eq!(g.class, ZinggClass::Rod);
    let mut xs: Vec<f64> = g.spheres.iter().map(|c| c.center.x).collect();
    xs.sort_by(f64::total_cmp);
    for (x, want) in xs.iter().zip([-1.0, 0.0, 1.0]) {
        assert!(close(*x, want, 1.0), "{xs:?}");
    }
    for c in &g.spheres {
        assert!(close(c.radius, 0.5, 1.0) && close(c.center.y, 0.0, 1.0) && close(c.center.z, 0.0, 1.0));
    }
    // Per sphere v = π/6 and own moment (2/5) v r² = v/10; the off-axis moment adds v·(1 + 1).
    let v = PI / 6.0;
    assert!(close(g.volume, 3.0 * v, 1.0));
    for (got, want) in g.inertia.iter().zip([0.3 * v, 2.3 * v, 2.3 * v]) {
        assert!(close(*got, want, 1.0), "{:?}", g.inertia);
    }
    // Rounding to the nearest integer: L/d_p = 2.4 gives 2 spheres, 2.6 gives 3.
    assert_eq!(construction(&form(2.4, 1.0, 1.0)).unwrap().1.len(), 2);
    assert_eq!(construction(&form(2.6, 1.0, 1.0)).unwrap().1.len(), 3);
    // (2, 0.8, 0.6): d_p = √0.48, L/d_p = 2.887 → 3 spheres of radius √0.48/2, 3 d_p long.
    let f = form(2.0, 0.8, 0.6);
    let (class, spheres) = construction(&f).unwrap();
    let dp = 0.48f64.sqrt();
    assert_eq!(class, ZinggClass::Rod);
    assert_signature(&spheres, &[dp / 2.0; 3], &[dp, dp, 2.0 * dp], 1.0);
    let e = extents(&spheres);
    assert!(close(e.x, 3.0 * dp, 1.0) && close(e.y, dp, 1.0) && close(e.z, dp, 1.0), "{e:?}");
}

#[test]
fn disk_is_a_hexagonal_patch_with_rows_of_nl_and_nl_minus_one() {
    // (3, 2.2, 1): d_p = 1, n_l = 3, n_i = [2.2] = 2 rows √3/2 apart; the upper middle row has 3
    // spheres, the lower 2, in its gaps.
    let f = form(3.0, 2.2, 1.0);
    let (class, spheres) = construction(&f).unwrap();
    assert_eq!(class, ZinggClass::Disk);
    let h = 3f64.sqrt() / 4.0;
    let want = [(-0.5, -h), (0.5, -h), (-1.0, h), (0.0, h), (1.0, h)];
    assert_eq!(spheres.len(), want.len());
    for (c, (x, y)) in spheres.iter().zip(want) {
        assert!(close(c.center.x, x, 1.0) && close(c.center.y, y, 1.0) && c.center.z == 0.0, "{spheres:?}");
        assert!(close(c.radius, 0.5, 1.0));
    }
    // Mass properties by hand, v = π/6 per sphere: ȳ = (−2h + 3h)/5 = √3/20; Σ(y − ȳ)² = 0.9,
    // Σx² = 2.5, own moments 5·v/10; no product of inertia (each row is symmetric in x).
    let g = bonded_grain(&f).unwrap();
    let v = PI / 6.0;
    assert!(close(g.volume, 5.0 * v, 1.0));
    assert!(close(g.center_of_mass.y, 3f64.sqrt() / 20.0, 1.0) && close(g.center_of_mass.x, 0.0, 1.0));
    for (got, want) in g.inertia.iter().zip([1.4 * v, 3.0 * v, 3.9 * v]) {
        assert!(close(*got, want, 1.0), "{:?}", g.inertia);
    }
    // The smallest moment is about D_l: the principal x axis is the construction's x axis.
    assert!(close(g.rotation.matrix()[(0, 0)].abs(), 1.0, 1.0));
}

#[test]
fn blade_lattice_counts_and_extent() {
    // (5, 3, 1): blade, d_p = 1, n_l = 5, n_i = 3: rows of 4, 5, 4 spheres, 13 in all.
    let (class, spheres) = construction(&form(5.0, 3.0, 1.0)).unwrap();
    assert_eq!(class, ZinggClass::Blade);
    assert_eq!(spheres.len(), 13);
    let middle: Vec<&ComponentSphere> = spheres.iter().filter(|c| c.center.y.abs() < 1e-12).collect();
    assert_eq!(middle.len(), 5);
    let e = extents(&spheres);
    // n_l d_p along D_l, d_p(1 + 2·√3/2) across three rows, d_p along D_s.
    assert!(close(e.x, 5.0, 1.0) && close(e.y, 1.0 + 3f64.sqrt(), 1.0) && close(e.z, 1.0, 1.0), "{e:?}");
    // Hexagonal lattice: every sphere's nearest neighbour touches it.
    for (k, a) in spheres.iter().enumerate() {
        let nearest = (spheres.iter().enumerate())
            .filter(|&(j, _)| j != k)
            .map(|(_, b)| (a.center - b.center).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(close(nearest, 1.0, 1.0));
    }
}

#[test]
fn equant_subtypes_follow_the_appendix() {
    // Subtype 1, (1, 0.95, 0.9): one sphere of (L I S)^(1/3), the ellipsoid's volume.
    let f = form(1.0, 0.95, 0.9);
    let g = bonded_grain(&f).unwrap();
    let d = 0.855f64.cbrt();
    assert_eq!(g.class, ZinggClass::Equant(1));
    assert_signature(&g.spheres, &[d / 2.0], &[], 1.0);
    assert!(close(g.volume, ellipsoid_mass(&f).volume, 1.0));
    assert!(g.inertia.iter().all(|&m| close(m, 0.1 * g.volume * d * d, 1.0)));
    assert!(close(g.bounding_radius, d / 2.0, 1.0));

    // Subtype 2, (1, 0.8, 0.76): main √(0.8·0.76), auxiliary 1 − main, touching, spanning L.
    let f = form(1.0, 0.8, 0.76);
    let g = bonded_grain(&f).unwrap();
    let main = 0.608f64.sqrt();
    let aux = 1.0 - main;
    assert_eq!(g.class, ZinggClass::Equant(2));
    assert_signature(&g.spheres, &[main / 2.0, aux / 2.0], &[0.5], 1.0);
    let (vm, va) = (PI * main.powi(3) / 6.0, PI * aux.powi(3) / 6.0);
    // Two point masses 0.5 apart: the transverse moment gains vm·va/(vm + va)·0.5².
    let own = 0.1 * (vm * main * main + va * aux * aux);
    let transverse = own + vm * va / (vm + va) * 0.25;
    for (got, want) in g.inertia.iter().zip([own, transverse, transverse]) {
        assert!(close(*got, want, 1.0), "{:?}", g.inertia);
    }
    let e = extents(&construction(&f).unwrap().1);
    assert!(close(e.x, 1.0, 1.0) && close(e.y, main, 1.0) && close(e.z, main, 1.0));

    // Subtype 3, (1, 0.95, 0.8): main 0.8, two auxiliaries of 0.2 touching it (centres 0.5 away)
    // at θ_e = 2 asin(0.75), so 2·0.5·0.75 = 0.75 = I − 0.2 apart: their outer faces span I.
    let f = form(1.0, 0.95, 0.8);
    let (class, spheres) = construction(&f).unwrap();
    assert_eq!(class, ZinggClass::Equant(3));
    assert_signature(&spheres, &[0.4, 0.1, 0.1], &[0.5, 0.5, 0.75], 1.0);
    let e = extents(&spheres);
    let across = 0.4 + 0.5 * (1.0 - 0.75f64.powi(2)).sqrt() + 0.1;
    assert!(close(e.x, across, 1.0) && close(e.y, 0.95, 1.0) && close(e.z, 0.8, 1.0), "{e:?}");

    // Subtype 4, (1, 0.8, 0.6): main 0.6, auxiliaries 0.2 touching it (centres 0.4 away), two
    // opposite (0.8 apart, spanning L) and one at θ_e = 2 asin((1.6 + 0.6 − 1)/1.6) = 2 asin(0.75)
    // from the first: 2·0.4·0.75 = 0.6 = I − 0.2 from it and 2·0.4·cos(asin 0.75) from the other.
    let f = form(1.0, 0.8, 0.6);
    let (class, spheres) = construction(&f).unwrap();
    assert_eq!(class, ZinggClass::Equant(4));
    let far = 0.8 * (1.0 - 0.75f64.powi(2)).sqrt();
    assert_signature(&spheres, &[0.3, 0.1, 0.1, 0.1], &[0.4, 0.4, 0.4, 0.8, 0.6, far], 1.0);
    let e = extents(&spheres);
    assert!(close(e.x, 1.0, 1.0) && close(e.z, 0.6, 1.0), "{e:?}");
}

/// The construction-frame extents each class should have, worked from the paper's rules.
fn expected_extents(f: &FormParameters, class: ZinggClass) -> Vector3<f64> {
    let (l, i, s) = (f.l, f.i, f.s);
    match class {
        ZinggClass::Disk | ZinggClass::Blade => {
            let (nl, ni) = ((l / s).round(), (i / s).round());
            Vector3::new(nl * s, s * (1.0 + (ni - 1.0) * 3f64.sqrt() / 2.0), s)
        }
        ZinggClass::Rod => {
            let dp = (s * i).sqrt();
            Vector3::new((l / dp).round() * dp, dp, dp)
        }
        ZinggClass::Equant(1) => Vector3::repeat((l * i * s).cbrt()),
        ZinggClass::Equant(2) => Vector3::new(l, (s * i).sqrt(), (s * i).sqrt()),
        ZinggClass::Equant(3) => {
            // From the main sphere's far side to the auxiliaries' outer faces along the
            // bisector, unless they stay within the main sphere's own reach.
            let half = ((i + s - l) / l).asin();
            Vector3::new(s / 2.0 + (s / 2.0).max(l / 2.0 * half.cos() + (l - s) / 2.0), i, s)
        }
        ZinggClass::Equant(_) => {
            // From the main sphere's bottom to the top of the main sphere or the third auxiliary.
            let (aux, r) = ((l - s) / 2.0, (l + s) / 4.0);
            let theta = 2.0 * ((2.0 * i + s - l) / (l + s)).asin();
            Vector3::new(l, s / 2.0 + (s / 2.0).max(r * theta.sin() + aux / 2.0), s)
        }
    }
}

#[test]
fn mass_properties_frames_and_layouts_of_random_grains() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut seen = BTreeMap::new();
    for _ in 0..3000 {
        let f = random_form(&mut rng);
        let g = bonded_grain(&f).unwrap();
        let (class, built) = construction(&f).unwrap();
        *seen.entry(class.name()).or_insert(0) += 1;
        let scale = f.l;
        assert_eq!(g.class, class);
        assert_eq!(g.spheres.len(), built.len());

        // Construction frame: the extents worked from the rules. They are not the L × I × S box
        // (see `expected_extents`); along D_l rounding adds at most half a sphere (n_l = [L/d_p]).
        let e = extents(&built);
        let want = expected_extents(&f, class);
        for k in 0..3 {
            assert!(close(e[k], want[k], scale), "{}: {e:?} vs {want:?} for {f:?}", class.name());
        }
        let largest_radius = built.iter().map(|c| c.radius).fold(0.0, f64::max);
        assert!(e.x <= f.l + largest_radius + 1e-12 * scale, "{}: {e:?} for {f:?}", class.name());

        // The output is the construction moved rigidly: x_c = R x_p + c.
        assert!(close(g.rotation.matrix().determinant(), 1.0, 1.0));
        for (p, c) in g.spheres.iter().zip(&built) {
            assert!((g.rotation * p.center + g.center_of_mass - c.center).norm() <= 1e-12 * scale);
            assert_eq!(p.radius, c.radius);
        }

        // Volume is the sum of the sphere volumes; centre of mass at the origin.
        let volumes: Vec<f64> = g.spheres.iter().map(|c| 4.0 / 3.0 * PI * c.radius.powi(3)).collect();
        let total: f64 = volumes.iter().sum();
        assert!(close(g.volume, total, total));
        let first: Vector3<f64> = g.spheres.iter().zip(&volumes).map(|(c, v)| *v * c.center).sum();
        assert!(first.norm() <= 1e-12 * total * scale);

        // Inertia written differently: second moment S = Σ v (c cᵀ + r²/5 𝟙), J = tr(S) 𝟙 − S;
        // diagonal in the output frame and ascending.
        let second: Matrix3<f64> = (g.spheres.iter().zip(&volumes))
            .map(|(c, v)| *v * (c.center * c.center.transpose() + Matrix3::identity() * (c.radius.powi(2) / 5.0)))
            .sum();
        let inertia = Matrix3::identity() * second.trace() - second;
        let largest = g.inertia.z;
        for r in 0..3 {
            for c in 0..3 {
                let want = if r == c { g.inertia[r] } else { 0.0 };
                assert!((inertia[(r, c)] - want).abs() <= 1e-10 * largest, "{inertia} vs {:?}", g.inertia);
            }
        }
        assert!(g.inertia.x <= g.inertia.y && g.inertia.y <= g.inertia.z);

        // The paper's spheres do not overlap (§2.4), and each touches another: one bonded body.
        let n = g.spheres.len();
        let mut touches = vec![n == 1; n];
        for a in 0..n {
            for b in a + 1..n {
                let (p, q) = (&g.spheres[a], &g.spheres[b]);
                let gap = (p.center - q.center).norm() - (p.radius + q.radius);
                assert!(gap >= -1e-12 * scale, "{} overlaps by {gap} in {f:?}", class.name());
                if gap <= 1e-12 * scale {
                    touches[a] = true;
                    touches[b] = true;
                }
            }
        }
        assert!(touches.iter().all(|&t| t), "{}: a sphere touches no other in {f:?}", class.name());

        // Bounding radius: encloses every sphere and touches one.
        let reach = g.spheres.iter().map(|c| c.center.norm() + c.radius).fold(0.0, f64::max);
        assert!(close(g.bounding_radius, reach, scale));
    }
    assert_eq!(seen.len(), 7, "every class drawn: {seen:?}");
}

#[test]
fn monte_carlo_volume_and_inertia_agree() {
    // One grain of each class; 400 000 points uniform in the spheres' bounding box. The box is at
    // least ~25 % solid, so the standard error is ≤ 0.4 % for the volume and ≤ 0.7 % for the
    // moments: 2 % is more than 3 standard errors.
    let forms = [
        (3.0, 2.2, 1.0),
        (5.0, 3.0, 1.0),
        (2.0, 0.8, 0.6),
        (1.0, 0.95, 0.9),
        (1.0, 0.8, 0.76),
        (1.0, 0.95, 0.8),
        (1.0, 0.8, 0.6),
    ];
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for (l, i, s) in forms {
        let g = bonded_grain(&form(l, i, s)).unwrap();
        let lo = g.spheres.iter().fold(Vector3::repeat(f64::INFINITY), |m, c| m.inf(&c.center.add_scalar(-c.radius)));
        let size = extents(&g.spheres);
        let samples = 400_000;
        let (mut hits, mut second) = (0usize, Matrix3::zeros());
        for _ in 0..samples {
            let p = lo + size.component_mul(&Vector3::new(rng.random(), rng.random(), rng.random()));
            if g.spheres.iter().any(|c| (p - c.center).norm_squared() <= c.radius * c.radius) {
                hits += 1;
                second += p * p.transpose();
            }
        }
        let cell = size.product() / samples as f64;
        let volume = hits as f64 * cell;
        let inertia = (Matrix3::identity() * second.trace() - second) * cell;
        assert!((volume / g.volume - 1.0).abs() < 0.02, "{}: volume {volume} vs {}", g.class, g.volume);
        for r in 0..3 {
            for c in 0..3 {
                let want = if r == c { g.inertia[r] } else { 0.0 };
                let tol = 0.02 * if r == c { g.inertia[r] } else { g.inertia.z };
                assert!((inertia[(r, c)] - want).abs() < tol, "{}: {inertia} vs {:?}", g.class, g.inertia);
            }
        }
    }
}

#[test]
fn ellipsoid_reference_matches_the_dem_ellipsoid() {
    let f = form(2.0e-3, 1.3e-3, 0.7e-3);
    let e = ellipsoid_mass(&f);
    let shape = Shape::Ellipsoid { semi_axes: Vector3::new(1.0e-3, 0.65e-3, 0.35e-3) };
    assert!(close(e.volume, shape.volume(), e.volume));
    assert!(close(e.volume, PI * 2.0e-3 * 1.3e-3 * 0.7e-3 / 6.0, e.volume));
    let moments = shape.principal_inertia(1.0);
    for k in 0..3 {
        assert!(close(e.inertia[k], moments[k], moments.max()));
    }
    assert!(e.inertia.x < e.inertia.y && e.inertia.y < e.inertia.z);
}

/// Ratios of the bonded grain to the ellipsoid with the same axes: volume (= mass at equal
/// density) and the three principal moments, smallest to largest.
fn ratios(g: &BondedGrain) -> [f64; 4] {
    let e = ellipsoid_mass(&g.form);
    [g.volume / e.volume, g.inertia.x / e.inertia.x, g.inertia.y / e.inertia.y, g.inertia.z / e.inertia.z]
}

/// Min, quartiles and max.
fn five_numbers(values: &mut [f64]) -> [f64; 5] {
    values.sort_by(f64::total_cmp);
    let at = |q: f64| values[((values.len() - 1) as f64 * q).round() as usize];
    [at(0.0), at(0.25), at(0.5), at(0.75), at(1.0)]
}

/// The paper's "within 25 %": between its dashed lines of slope 0.80 and 1.25 (§3, Fig. 5).
fn within_25_percent(r: f64) -> bool {
    (0.8..=1.25).contains(&r)
}

/// Prints the distribution per class and overall; returns, for volume and each moment, the
/// fraction within 25 % and the overall (min, max).
fn report(grains: &[BondedGrain]) -> [(f64, f64, f64); 4] {
    let names = ["volume", "J1", "J2", "J3"];
    let mut per_class: BTreeMap<&str, Vec<[f64; 4]>> = BTreeMap::new();
    for g in grains {
        per_class.entry(g.class.name()).or_default().push(ratios(g));
    }
    println!("{} grains, bonded / ellipsoid: min q1 median q3 max", grains.len());
    for (class, rows) in &per_class {
        for (k, name) in names.iter().enumerate() {
            let mut column: Vec<f64> = rows.iter().map(|r| r[k]).collect();
            let q = five_numbers(&mut column);
            println!("{class:9} n={:5} {name:6} {q:.3?}", rows.len());
        }
    }
    let all: Vec<[f64; 4]> = grains.iter().map(ratios).collect();
    std::array::from_fn(|k| {
        let mut column: Vec<f64> = all.iter().map(|r| r[k]).collect();
        let within = column.iter().filter(|&&r| within_25_percent(r)).count() as f64 / column.len() as f64;
        let q = five_numbers(&mut column);
        println!("all               {:6} {q:.3?} within 25 %: {within:.3}", names[k]);
        (within, q[0], q[4])
    })
}

#[test]
fn a_priori_test_of_section_3_against_the_ellipsoid() {
    // The paper's test (§3, Fig. 5): 100 grains. Its claim that all lie within 25 % of the
    // ellipsoid does not hold for the construction as written (DESIGN.md, "Bonded spheres, a
    // caution"); asserted here is what the construction gives. The expected fractions come from
    // a 100 000-grain run of the same sampling (volume 0.645, J1 0.489, J2 0.314, J3 0.340);
    // with 100 grains a fraction has a binomial standard deviation of at most 0.05, so ±0.15 is
    // three of them and holds for any seed with 99.7 % probability.
    let grains = random_grains(100, 2017);
    let mut classes = BTreeMap::new();
    for g in &grains {
        *classes.entry(g.class.name()).or_insert(0) += 1;
    }
    println!("class mix: {classes:?}");
    // Uniform D_i/D_l and D_s/D_i in 0.3–1 put ≈ 25 % in each Zingg quadrant (Fig. 4 has all four).
    for class in ["disk", "blade", "rod"] {
        assert!((10..=40).contains(classes.get(class).unwrap_or(&0)), "{classes:?}");
    }
    let stats = report(&grains);
    for ((within, _, _), expected) in stats.iter().zip([0.645, 0.489, 0.314, 0.340]) {
        assert!((within - expected).abs() <= 0.15, "fraction within 25 %: {within} vs {expected}");
    }
    // The paper's claim, all within 25 %, fails for volume and every moment.
    assert!(stats.iter().all(|&(within, _, _)| within < 1.0));
}

#[test]
fn ratio_distribution_over_many_grains() {
    // 20 000 grains pin the distribution down: a fraction's binomial standard deviation is
    // ≤ 0.0035, so ±0.015 (4 of them) around the 100 000-grain values; the extremes lie inside
    // that run's envelope (volume 0.441–1.331, moments 0.240–2.862) widened by 2 %.
    let grains = random_grains(20_000, 1);
    let stats = report(&grains);
    for ((within, _, _), expected) in stats.iter().zip([0.645, 0.489, 0.314, 0.340]) {
        assert!((within - expected).abs() <= 0.015, "fraction within 25 %: {within} vs {expected}");
    }
    let (volume_min, volume_max) = (stats[0].1, stats[0].2);
    assert!(volume_min >= 0.441 * 0.98 && volume_max <= 1.331 * 1.02, "volume {volume_min}–{volume_max}");
    for &(_, min, max) in &stats[1..] {
        assert!(min >= 0.240 * 0.98 && max <= 2.862 * 1.02, "moment {min}–{max}");
    }
    // Exact per-class facts: subtype 1 keeps the ellipsoid's volume; a rod's volume ratio is
    // n_l d_p / D_l, off by at most half a sphere; subtypes 2–4 are always lighter.
    for g in &grains {
        let [volume, ..] = ratios(g);
        let f = g.form;
        match g.class {
            ZinggClass::Equant(1) => assert!(close(volume, 1.0, 1.0)),
            ZinggClass::Rod => assert!((volume - 1.0).abs() <= (f.s * f.i).sqrt() / (2.0 * f.l) + 1e-12),
            ZinggClass::Equant(_) => assert!(volume < 1.0, "{f:?}: {volume}"),
            _ => {}
        }
    }
}
