//! Grain shapes as rigid bodies: volume, principal moments of inertia and bounding sphere, all
//! in the body frame, whose axes are the principal axes of inertia.

use nalgebra::{UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use super::contact::ellipsoid::EllipsoidPose;
use crate::grain::FormParameters;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Shape {
    Sphere {
        radius: f64,
    },
    /// Semi-axes along the body x, y, z axes.
    Ellipsoid {
        semi_axes: Vector3<f64>,
    },
}

impl Shape {
    pub fn volume(&self) -> f64 {
        let four_thirds_pi = 4.0 / 3.0 * std::f64::consts::PI;
        match self {
            Shape::Sphere { radius } => four_thirds_pi * radius.powi(3),
            Shape::Ellipsoid { semi_axes: s } => four_thirds_pi * s.x * s.y * s.z,
        }
    }

    /// Principal moments of inertia about the body axes for a solid of the given density.
    pub fn principal_inertia(&self, density: f64) -> Vector3<f64> {
        let m = density * self.volume();
        match self {
            Shape::Sphere { radius } => Vector3::repeat(0.4 * m * radius * radius),
            Shape::Ellipsoid { semi_axes: s } => {
                let (a2, b2, c2) = (s.x * s.x, s.y * s.y, s.z * s.z);
                Vector3::new(b2 + c2, a2 + c2, a2 + b2) * (m / 5.0)
            }
        }
    }

    /// Radius of the smallest sphere about the centre of mass enclosing the shape.
    pub fn bounding_radius(&self) -> f64 {
        match self {
            Shape::Sphere { radius } => *radius,
            Shape::Ellipsoid { semi_axes } => semi_axes.max(),
        }
    }

    /// Smallest half-thickness, the scale against which overlaps are judged.
    pub fn smallest_half_extent(&self) -> f64 {
        match self {
            Shape::Sphere { radius } => *radius,
            Shape::Ellipsoid { semi_axes } => semi_axes.min(),
        }
    }

    /// L, I, S of the shape (full axes of its mass-equivalent ellipsoid, which for a sphere or an
    /// ellipsoid is the shape itself).
    pub fn form(&self) -> FormParameters {
        match self {
            Shape::Sphere { radius } => FormParameters { l: 2.0 * radius, i: 2.0 * radius, s: 2.0 * radius },
            Shape::Ellipsoid { semi_axes } => {
                FormParameters::from_unsorted((2.0 * semi_axes).into()).expect("positive semi-axes")
            }
        }
    }

    /// A triangulated surface in the body frame, for visualisation: the unit icosphere subdivided
    /// `level` times, stretched to the shape.
    pub fn surface(&self, level: usize) -> (Vec<Vector3<f64>>, Vec<[u32; 3]>) {
        let (mut vertices, triangles) = unit_icosphere(level);
        let scale = match self {
            Shape::Sphere { radius } => Vector3::repeat(*radius),
            Shape::Ellipsoid { semi_axes } => *semi_axes,
        };
        for v in &mut vertices {
            *v = v.component_mul(&scale);
        }
        (vertices, triangles)
    }

    /// The precomputed ellipsoid of the narrow phase for a body at `position` turned by
    /// `orientation`; None for spheres, whose contacts are analytic.
    pub fn pose(&self, position: Vector3<f64>, orientation: &UnitQuaternion<f64>) -> Option<EllipsoidPose> {
        match self {
            Shape::Sphere { .. } => None,
            Shape::Ellipsoid { semi_axes } => {
                Some(EllipsoidPose::new(position, orientation.to_rotation_matrix().matrix(), *semi_axes))
            }
        }
    }

    /// Radius of the sphere of equal volume (used by the porosity evaluation, §4.4).
    pub fn equivalent_radius(&self) -> f64 {
        (self.volume() * 3.0 / (4.0 * std::f64::consts::PI)).cbrt()
    }
}

/// An icosahedron with each triangle split into four `level` times, vertices on the unit sphere.
fn unit_icosphere(level: usize) -> (Vec<Vector3<f64>>, Vec<[u32; 3]>) {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut vertices: Vec<Vector3<f64>> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|p| Vector3::from(*p).normalize())
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let mut midpoints = std::collections::HashMap::new();
        let mut midpoint = |a: u32, b: u32, vertices: &mut Vec<Vector3<f64>>| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                vertices.push(((vertices[a as usize] + vertices[b as usize]) / 2.0).normalize());
                (vertices.len() - 1) as u32
            })
        };
        triangles = triangles
            .iter()
            .flat_map(|&[a, b, c]| {
                let ab = midpoint(a, b, &mut vertices);
                let bc = midpoint(b, c, &mut vertices);
                let ca = midpoint(c, a, &mut vertices);
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    (vertices, triangles)
}
