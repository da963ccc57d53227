//! The mass-equivalent ellipsoid of Appendix A (Eqs. 25–27): the ellipsoid with the same mass
//! and principal moments of inertia as a grain, whose full axes are the grain's L, I, S.

use nalgebra::{Matrix3, Rotation3, SymmetricEigen, Vector3};

use super::form::{FormError, FormParameters};
use super::mesh::MassProperties;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EquivalentEllipsoid {
    /// Semi-axes a ≥ b ≥ c.
    pub semi_axes: Vector3<f64>,
    pub center: Vector3<f64>,
    /// Maps the ellipsoid's frame (x along a, y along b, z along c) to the mesh's frame; a proper
    /// rotation, so the grain is never mirrored.
    pub rotation: Rotation3<f64>,
}

impl EquivalentEllipsoid {
    /// Eqs. 25–27: a = sqrt(5(−I_x + I_y + I_z)/(2m)) and cyclically, with I_x, I_y, I_z the
    /// principal moments; the largest semi-axis belongs to the smallest moment.
    pub fn of(props: &MassProperties) -> Self {
        let (rotation, moments) = principal_frame(&props.inertia);
        let total: f64 = moments.iter().sum();
        let m = props.volume;
        // −I_x + I_y + I_z = total − 2 I_x.
        let semi_axes = moments.map(|ix| (5.0 * (total - 2.0 * ix) / (2.0 * m)).max(0.0).sqrt());
        Self { semi_axes, center: props.center_of_mass, rotation }
    }

    /// L = 2a, I = 2b, S = 2c.
    pub fn form(&self) -> Result<FormParameters, FormError> {
        let f = 2.0 * self.semi_axes;
        FormParameters::new(f.x, f.y, f.z)
    }
}

/// Principal axes of an inertia tensor as the columns of a proper rotation, and the principal
/// moments, ascending. The moments are the eigenvalues themselves, so equal moments (a rod, a
/// single sphere) cannot come out of order by rounding.
pub(crate) fn principal_frame(inertia: &Matrix3<f64>) -> (Rotation3<f64>, Vector3<f64>) {
    let eigen = SymmetricEigen::new(*inertia);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&p, &q| eigen.eigenvalues[p].total_cmp(&eigen.eigenvalues[q]));
    let mut axes = Matrix3::from_columns(&order.map(|k| eigen.eigenvectors.column(k).into_owned()));
    if axes.determinant() < 0.0 {
        axes.set_column(2, &(-axes.column(2)));
    }
    (Rotation3::from_matrix_unchecked(axes), Vector3::from(order.map(|k| eigen.eigenvalues[k])))
}
