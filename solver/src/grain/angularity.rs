//! How angular a grain is beyond its form: its sphericity against that of its mass-equivalent
//! ellipsoid (Appendix A), which has the grain's L, I, S. Form alone sets the ellipsoid's
//! sphericity; flat facets and sharp edges add surface and take volume from the ellipsoid that
//! shares the grain's inertia, so the ratio of the two sphericities (1 for an ellipsoid, 0.806
//! for a cube) measures what a packing of the grain sees of its angularity at a given form.
//! Meshes and ellipsoids of one form pack differently (§6.4, Fig. 10): these are properties in
//! which two mesh libraries of the same forms can still differ, at the surface (sphericity) and
//! in the bulk (volume ratio).

use super::ellipsoid::EquivalentEllipsoid;
use super::form::{FormError, FormParameters};
use super::mesh::TriMesh;
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
}

impl Angularity {
    pub fn of(mesh: &TriMesh) -> Result<Self, FormError> {
        let props = mesh.mass_properties();
        let ellipsoid = EquivalentEllipsoid::of(&props);
        let form = ellipsoid.form()?;
        let surface: f64 = (0..mesh.triangles().len())
            .map(|t| {
                let [a, b, c] = mesh.triangle(t);
                0.5 * (b - a).cross(&(c - a)).norm()
            })
            .sum();
        let ellipsoid_volume = form.ellipsoid_volume();
        Ok(Self {
            form,
            sphericity: equal_volume_sphere_surface(props.volume) / surface,
            ellipsoid_sphericity: equal_volume_sphere_surface(ellipsoid_volume)
                / ellipsoid_surface(&ellipsoid.semi_axes),
            volume_ratio: props.volume / ellipsoid_volume,
        })
    }

    /// The mesh's sphericity over its ellipsoid's: 1 for an ellipsoid, less the more angular.
    pub fn relative_sphericity(&self) -> f64 {
        self.sphericity / self.ellipsoid_sphericity
    }
}
