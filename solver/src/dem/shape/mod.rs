//! Grain shapes as rigid bodies: volume, principal moments of inertia and bounding sphere, all
//! in the body frame, whose axes are the principal axes of inertia; and the convex pieces the
//! narrow phase meets (one for a convex grain, one per component sphere of a bonded grain).

pub mod polyhedron;
pub(crate) mod table;

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

pub use self::polyhedron::{ConvexPolyhedron, Polyhedron, PolyhedronError};
use super::contact::Piece;
use super::contact::ellipsoid::EllipsoidPose;
use super::contact::support::PolyhedronPose;
use crate::grain::{BondedGrain, ComponentSphere, FormParameters};

/// A grain's shape. Polyhedra share their base mesh; a list of shapes is stored with each base
/// mesh once (`table`).
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    Sphere {
        radius: f64,
    },
    /// Semi-axes along the body x, y, z axes.
    Ellipsoid {
        semi_axes: Vector3<f64>,
    },
    /// Rigidly bonded, non-overlapping spheres (Sun & Xiao §2.4) in the principal-axes frame with
    /// the centre of mass at the origin; contacts are those of the component spheres.
    Bonded(Box<Bonded>),
    /// A convex polyhedron (a grain mesh, §3.1) in its principal-axes frame, centre of mass at
    /// the origin.
    Polyhedron(Box<Polyhedron>),
}

/// The component spheres of a bonded grain with its mass properties, precomputed once.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Bonded {
    pub spheres: Vec<ComponentSphere>,
    pub volume: f64,
    /// Principal moments per unit density along the body axes.
    pub inertia: Vector3<f64>,
    pub bounding_radius: f64,
    /// The axes the grain was built for.
    pub form: FormParameters,
}

impl From<&BondedGrain> for Shape {
    fn from(grain: &BondedGrain) -> Self {
        Shape::Bonded(Box::new(Bonded {
            spheres: grain.spheres.clone(),
            volume: grain.volume,
            inertia: grain.inertia,
            bounding_radius: grain.bounding_radius,
            form: grain.form,
        }))
    }
}

impl Shape {
    pub fn volume(&self) -> f64 {
        let four_thirds_pi = 4.0 / 3.0 * std::f64::consts::PI;
        match self {
            Shape::Sphere { radius } => four_thirds_pi * radius.powi(3),
            Shape::Ellipsoid { semi_axes: s } => four_thirds_pi * s.x * s.y * s.z,
            Shape::Bonded(b) => b.volume,
            Shape::Polyhedron(p) => p.volume,
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
            Shape::Bonded(b) => b.inertia * density,
            Shape::Polyhedron(p) => p.inertia * density,
        }
    }

    /// Radius of the smallest sphere about the centre of mass enclosing the shape.
    pub fn bounding_radius(&self) -> f64 {
        match self {
            Shape::Sphere { radius } => *radius,
            Shape::Ellipsoid { semi_axes } => semi_axes.max(),
            Shape::Bonded(b) => b.bounding_radius,
            Shape::Polyhedron(p) => p.bounding_radius,
        }
    }

    /// Largest horizontal distance of the shape's points from its centre of mass when turned by
    /// `orientation`: what a grain needs of a cylinder's radius around its centre.
    pub fn horizontal_reach(&self, orientation: &UnitQuaternion<f64>) -> f64 {
        let rotation = orientation.to_rotation_matrix().into_inner();
        let horizontal = |v: Vector3<f64>| v.x.hypot(v.y);
        match self {
            Shape::Sphere { radius } => *radius,
            // The ellipsoid's shadow on the plane is the ellipse of the 2 × 2 upper block of
            // R diag(a², b², c²) Rᵀ; its largest semi-axis is the root of that block's larger
            // eigenvalue.
            Shape::Ellipsoid { semi_axes } => {
                let m = rotation * Matrix3::from_diagonal(&semi_axes.component_mul(semi_axes)) * rotation.transpose();
                let (mean, half_gap) =
                    ((m[(0, 0)] + m[(1, 1)]) / 2.0, ((m[(0, 0)] - m[(1, 1)]) / 2.0).hypot(m[(0, 1)]));
                (mean + half_gap).sqrt()
            }
            Shape::Bonded(b) => {
                b.spheres.iter().map(|c| horizontal(rotation * c.center) + c.radius).fold(0.0, f64::max)
            }
            Shape::Polyhedron(p) => {
                let map = rotation * Matrix3::from_diagonal(&p.scale);
                p.base.vertices().iter().map(|v| horizontal(map * v)).fold(0.0, f64::max)
            }
        }
    }

    /// Largest extent of the shape beyond its centre of mass along the unit `direction` when
    /// turned by `orientation` (its support function): how far above its centre a grain reaches
    /// for `direction` = ẑ.
    pub fn reach_along(&self, orientation: &UnitQuaternion<f64>, direction: &Vector3<f64>) -> f64 {
        let d = orientation.inverse_transform_vector(direction);
        match self {
            Shape::Sphere { radius } => *radius,
            Shape::Ellipsoid { semi_axes } => semi_axes.component_mul(&d).norm(),
            Shape::Bonded(b) => b.spheres.iter().map(|c| c.center.dot(&d) + c.radius).fold(f64::MIN, f64::max),
            Shape::Polyhedron(p) => {
                let d = p.scale.component_mul(&d);
                p.base.vertices().iter().map(|v| v.dot(&d)).fold(f64::MIN, f64::max)
            }
        }
    }

    /// L, I, S of the shape: the full axes of a sphere or ellipsoid, the axes a bonded grain was
    /// built for.
    pub fn form(&self) -> FormParameters {
        match self {
            Shape::Sphere { radius } => FormParameters { l: 2.0 * radius, i: 2.0 * radius, s: 2.0 * radius },
            Shape::Ellipsoid { semi_axes } => {
                FormParameters::from_unsorted((2.0 * semi_axes).into()).expect("positive semi-axes")
            }
            Shape::Bonded(b) => b.form,
            Shape::Polyhedron(p) => p.form,
        }
    }

    /// Bytes the shape holds outside its own enum (a polyhedron's shared base mesh excluded).
    pub fn heap_bytes(&self) -> usize {
        match self {
            Shape::Sphere { .. } | Shape::Ellipsoid { .. } => 0,
            Shape::Bonded(b) => std::mem::size_of::<Bonded>() + std::mem::size_of_val(&b.spheres[..]),
            Shape::Polyhedron(_) => std::mem::size_of::<Polyhedron>(),
        }
    }

    /// Number of convex pieces the narrow phase meets.
    #[inline]
    pub fn pieces(&self) -> usize {
        match self {
            Shape::Bonded(b) => b.spheres.len(),
            _ => 1,
        }
    }

    /// Piece `k` of a body at `position` turned by `orientation`, with the `pose` of this
    /// step ([`Shape::pose`]). Inline for the sphere, the rest out of line.
    #[inline(always)]
    pub fn piece<'a>(
        &'a self,
        k: usize,
        position: Vector3<f64>,
        orientation: &UnitQuaternion<f64>,
        pose: &'a Pose,
    ) -> Piece<'a> {
        match self {
            Shape::Sphere { radius } => Piece::Sphere { center: position, radius: *radius },
            _ => self.non_spherical_piece(k, position, orientation, pose),
        }
    }

    #[inline(never)]
    fn non_spherical_piece<'a>(
        &'a self,
        k: usize,
        position: Vector3<f64>,
        orientation: &UnitQuaternion<f64>,
        pose: &'a Pose,
    ) -> Piece<'a> {
        match (self, pose) {
            (Shape::Sphere { .. }, _) => unreachable!("spheres are handled inline by `piece`"),
            (Shape::Ellipsoid { .. }, Pose::Ellipsoid(pose)) => Piece::Ellipsoid { pose, center: position },
            (Shape::Bonded(b), _) => {
                let c = &b.spheres[k];
                Piece::Sphere { center: position + orientation * c.center, radius: c.radius }
            }
            (Shape::Polyhedron(p), Pose::Polyhedron(frame)) => {
                Piece::Polyhedron(PolyhedronPose::with_frame(p, frame, position))
            }
            _ => unreachable!("a body's pose is made for its shape"),
        }
    }

    /// Centre (body frame) and bounding radius of piece `k`.
    pub fn piece_bounds(&self, k: usize) -> (Vector3<f64>, f64) {
        match self {
            Shape::Bonded(b) => (b.spheres[k].center, b.spheres[k].radius),
            _ => (Vector3::zeros(), self.bounding_radius()),
        }
    }

    /// A triangulated surface in the body frame, for visualisation: a polyhedron's own faces, or
    /// unit icospheres subdivided `level` times, stretched to the shape (one per component
    /// sphere of a bonded grain).
    pub fn surface(&self, level: usize) -> (Vec<Vector3<f64>>, Vec<[u32; 3]>) {
        let (unit, triangles) = unit_icosphere(level);
        let stretched =
            |scale: Vector3<f64>, offset: Vector3<f64>| unit.iter().map(move |v| offset + v.component_mul(&scale));
        match self {
            Shape::Sphere { radius } => (stretched(Vector3::repeat(*radius), Vector3::zeros()).collect(), triangles),
            Shape::Ellipsoid { semi_axes } => (stretched(*semi_axes, Vector3::zeros()).collect(), triangles),
            Shape::Polyhedron(p) => p.surface(),
            Shape::Bonded(b) => {
                let mut vertices = Vec::with_capacity(unit.len() * b.spheres.len());
                let mut all = Vec::with_capacity(triangles.len() * b.spheres.len());
                for c in &b.spheres {
                    let offset = vertices.len() as u32;
                    vertices.extend(stretched(Vector3::repeat(c.radius), c.center));
                    all.extend(triangles.iter().map(|t| t.map(|v| v + offset)));
                }
                (vertices, all)
            }
        }
    }

    /// What the narrow phase precomputes of a body at `position` turned by `orientation`, once
    /// per step: nothing for shapes met as spheres.
    pub fn pose(&self, position: Vector3<f64>, orientation: &UnitQuaternion<f64>) -> Pose {
        match self {
            Shape::Ellipsoid { semi_axes } => {
                Pose::Ellipsoid(EllipsoidPose::new(position, orientation.to_rotation_matrix().matrix(), *semi_axes))
            }
            Shape::Polyhedron(p) => Pose::Polyhedron(PolyhedronFrame::new(orientation, &p.scale)),
            Shape::Sphere { .. } | Shape::Bonded(_) => Pose::None,
        }
    }

    /// Radius of the sphere of equal volume (used by the porosity evaluation, §4.4).
    pub fn equivalent_radius(&self) -> f64 {
        (self.volume() * 3.0 / (4.0 * std::f64::consts::PI)).cbrt()
    }
}

/// A body's shape turned into the world for one step, computed once per step.
#[derive(Debug, Clone, Default)]
pub enum Pose {
    /// Spheres and bonded grains: the centre and orientation are all the narrow phase needs.
    #[default]
    None,
    Ellipsoid(EllipsoidPose),
    Polyhedron(PolyhedronFrame),
}

impl Pose {
    pub fn is_some(&self) -> bool {
        !matches!(self, Pose::None)
    }
}

/// A stretched polyhedron's body-to-world maps: vertices x = R S v, face normals ∝ R S⁻¹ n.
#[derive(Debug, Clone, Copy)]
pub struct PolyhedronFrame {
    pub map: Matrix3<f64>,
    pub normal_map: Matrix3<f64>,
}

impl PolyhedronFrame {
    pub fn new(orientation: &UnitQuaternion<f64>, scale: &Vector3<f64>) -> Self {
        let r = orientation.to_rotation_matrix().into_inner();
        Self { map: r * Matrix3::from_diagonal(scale), normal_map: r * Matrix3::from_diagonal(&scale.map(|s| 1.0 / s)) }
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
