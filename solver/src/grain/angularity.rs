//! How angular a grain is beyond its form: its sphericity against that of its mass-equivalent
//! ellipsoid (Appendix A), which has the grain's L, I, S. Form alone sets the ellipsoid's
//! sphericity; flat facets and sharp edges add surface and take volume from the ellipsoid that
//! shares the grain's inertia, so the ratio of the two sphericities (1 for an ellipsoid, 0.806
//! for a cube) measures what a packing of the grain sees of its angularity at a given form.
//! Meshes and ellipsoids of one form pack differently (§6.4, Fig. 10): these are properties in
//! which two mesh libraries of the same forms can still differ, at the surface (sphericity) and
//! in the bulk (volume ratio).

use std::collections::HashMap;

use super::ellipsoid::EquivalentEllipsoid;
use super::form::{FormError, FormParameters};
use super::mesh::TriMesh;
use super::unit_mesh::UnitMesh;
use crate::fluid::sphericity::{ellipsoid_surface, equal_volume_sphere_surface};

/// Sphericities of a grain mesh and of its mass-equivalent ellipsoid, with the volume ratio.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Angularity {
    /// The mesh's own form (its equivalent ellipsoid's full axes).
    pub form: FormParameters,
    /// Wadell's sphericity of the mesh: surface of the sphere of equal volume over its surface.
    pub sphericity: f64,
    /// The same of its mass-equivalent ellipsoid.
    pub ellipsoid_sphericity: f64,
    /// Mesh volume over that ellipsoid's volume: 1 for an ellipsoid, which has the most volume
    /// for its second moments, lower the more the bulk departs from one; a stretch along the
    /// principal axes leaves it unchanged, so a mesh keeps it at every form it is rescaled to.
    pub volume_ratio: f64,
    /// Share of the surface on its largest facet ([`largest_facet`]) with the form removed (the
    /// mesh stretched to L = I = S, as a packing's library holds it, Fig. 5b): 1/6 for any box,
    /// near 0 for a fine mesh of a smooth grain. A stretch flattens a curved side, so only a
    /// true plane, a fracture face or a cut, is a large facet at every form.
    pub largest_facet: f64,
    /// Distance of the farthest vertex from the centre with the form removed, in semi-axes of
    /// the mass-equivalent ellipsoid: near 1 for a fine mesh of an ellipsoid, 3/√5 = 1.342 for
    /// any box. Tips and corners that reach beyond the ellipsoid raise it, and a stretch along
    /// the principal axes leaves it unchanged.
    pub farthest_vertex: f64,
}

impl Angularity {
    pub fn of(mesh: &TriMesh) -> Result<Self, FormError> {
        let props = mesh.mass_properties();
        let ellipsoid = EquivalentEllipsoid::of(&props);
        let unit = UnitMesh::with_ellipsoid(mesh, &ellipsoid)?;
        let form = unit.original_form();
        let surface = mesh.surface();
        let ellipsoid_volume = form.ellipsoid_volume();
        // The unit mesh's ellipsoid has semi-axes 1/2.
        let farthest_vertex = unit.mesh().vertices().iter().map(|v| 2.0 * v.norm()).fold(0.0, f64::max);
        Ok(Self {
            form,
            sphericity: equal_volume_sphere_surface(props.volume) / surface,
            ellipsoid_sphericity: equal_volume_sphere_surface(ellipsoid_volume)
                / ellipsoid_surface(&ellipsoid.semi_axes),
            volume_ratio: props.volume / ellipsoid_volume,
            largest_facet: largest_facet(unit.mesh()),
            farthest_vertex,
        })
    }

    /// The mesh's sphericity over its ellipsoid's: 1 for an ellipsoid, less the more angular.
    pub fn relative_sphericity(&self) -> f64 {
        self.sphericity / self.ellipsoid_sphericity
    }
}

/// Normals within this angle of a facet's first triangle's lie on that facet: a flat face
/// triangulated by a hull or a simplification, not the gently curved faces of a fine mesh.
pub const FACET_ANGLE_DEGREES: f64 = 3.0;

/// Share of the mesh's surface on its largest facet: triangles joined across edges whose normals all lie within
/// [`FACET_ANGLE_DEGREES`] of the facet's first (largest) triangle's, grown from the largest
/// triangle not yet on a facet, so that a smooth surface cannot chain into one facet.
pub fn largest_facet(mesh: &TriMesh) -> f64 {
    let n = mesh.triangles().len();
    let (mut normals, mut areas) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for t in 0..n {
        let [a, b, c] = mesh.triangle(t);
        let cross = (b - a).cross(&(c - a));
        areas.push(0.5 * cross.norm());
        normals.push(cross.normalize());
    }
    let mut by_edge: HashMap<(u32, u32), Vec<usize>> = HashMap::with_capacity(3 * n);
    for (t, tri) in mesh.triangles().iter().enumerate() {
        for k in 0..3 {
            let (p, q) = (tri[k], tri[(k + 1) % 3]);
            by_edge.entry((p.min(q), p.max(q))).or_default().push(t);
        }
    }
    let within = FACET_ANGLE_DEGREES.to_radians().cos();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| areas[b].total_cmp(&areas[a]));
    let mut on_facet = vec![false; n];
    let (mut largest, mut stack) = (0.0_f64, Vec::new());
    for first in order {
        if on_facet[first] {
            continue;
        }
        on_facet[first] = true;
        stack.push(first);
        let mut area = 0.0;
        while let Some(t) = stack.pop() {
            area += areas[t];
            let tri = mesh.triangles()[t];
            for k in 0..3 {
                let (p, q) = (tri[k], tri[(k + 1) % 3]);
                for &next in &by_edge[&(p.min(q), p.max(q))] {
                    if !on_facet[next] && normals[next].dot(&normals[first]) > within {
                        on_facet[next] = true;
                        stack.push(next);
                    }
                }
            }
        }
        largest = largest.max(area);
    }
    largest / areas.iter().sum::<f64>()
}
