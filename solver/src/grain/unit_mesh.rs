//! Fig. 5 of the paper: a mesh with its form removed (centre of mass at the origin, principal
//! axes along x, y, z, scaled so that L = I = S = 1), rescaled per grain to a target (L̂, Î, Ŝ).

use nalgebra::Vector3;

use super::ellipsoid::EquivalentEllipsoid;
use super::form::{FormError, FormParameters};
use super::mesh::TriMesh;

/// A grain mesh whose mass-equivalent ellipsoid is the unit sphere of diameter 1, with the
/// long axis along x, the intermediate along y and the short along z.
#[derive(Debug, Clone)]
pub struct UnitMesh {
    mesh: TriMesh,
    /// The form the mesh had before normalisation (its "own form", §5.1).
    original: FormParameters,
}

impl UnitMesh {
    /// Fig. 5a → 5b. Scaling along principal axes keeps them principal and scales each semi-axis
    /// of the equivalent ellipsoid by exactly its factor, so one pass suffices.
    pub fn new(mesh: &TriMesh) -> Result<Self, FormError> {
        Self::with_ellipsoid(mesh, &EquivalentEllipsoid::of(&mesh.mass_properties()))
    }

    /// As [`UnitMesh::new`], for a caller that already holds the mesh's equivalent ellipsoid.
    pub fn with_ellipsoid(mesh: &TriMesh, ellipsoid: &EquivalentEllipsoid) -> Result<Self, FormError> {
        let original = ellipsoid.form()?;
        let inverse_axes = Vector3::new(1.0 / original.l, 1.0 / original.i, 1.0 / original.s);
        let rotation_inverse = ellipsoid.rotation.inverse();
        let center = ellipsoid.center;
        let unit = mesh.map_vertices(|v| (rotation_inverse * (v - center)).component_mul(&inverse_axes));
        Ok(Self { mesh: unit, original })
    }

    pub fn mesh(&self) -> &TriMesh {
        &self.mesh
    }

    pub fn original_form(&self) -> FormParameters {
        self.original
    }

    /// Fig. 5b → 5c: the mesh stretched by (L̂, Î, Ŝ) along x, y, z.
    pub fn rescaled(&self, form: &FormParameters) -> TriMesh {
        let scale = Vector3::new(form.l, form.i, form.s);
        self.mesh.map_vertices(|v| v.component_mul(&scale))
    }
}
