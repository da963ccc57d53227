//! How a list of shapes is stored in a checkpoint: each polyhedron base mesh once, the grains
//! by index into that list with their stretch, so that a bed of thousands of grains drawn from
//! a few scans stores a few meshes, not thousands.

use std::sync::Arc;

use nalgebra::Vector3;
use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::{Bonded, ConvexPolyhedron, Polyhedron, Shape};
use crate::grain::TriMesh;

#[derive(Serialize, Deserialize)]
struct Stored {
    meshes: Vec<MeshRecord>,
    shapes: Vec<ShapeRecord>,
}

#[derive(Serialize, Deserialize)]
struct MeshRecord {
    vertices: Vec<Vector3<f64>>,
    triangles: Vec<[u32; 3]>,
}

#[derive(Serialize, Deserialize)]
enum ShapeRecord {
    Sphere { radius: f64 },
    Ellipsoid { semi_axes: Vector3<f64> },
    Bonded(Box<Bonded>),
    Polyhedron { mesh: u32, scale: Vector3<f64> },
}

pub fn serialize<S: Serializer>(shapes: &[Shape], serializer: S) -> Result<S::Ok, S::Error> {
    let mut bases: Vec<&Arc<ConvexPolyhedron>> = Vec::new();
    let records = shapes
        .iter()
        .map(|shape| match shape {
            Shape::Sphere { radius } => ShapeRecord::Sphere { radius: *radius },
            Shape::Ellipsoid { semi_axes } => ShapeRecord::Ellipsoid { semi_axes: *semi_axes },
            Shape::Bonded(b) => ShapeRecord::Bonded(b.clone()),
            Shape::Polyhedron(p) => {
                let mesh = match bases.iter().position(|b| Arc::ptr_eq(b, &p.base) || **b == p.base) {
                    Some(k) => k,
                    None => {
                        bases.push(&p.base);
                        bases.len() - 1
                    }
                };
                ShapeRecord::Polyhedron { mesh: mesh as u32, scale: p.scale }
            }
        })
        .collect();
    let meshes = bases
        .iter()
        .map(|b| MeshRecord { vertices: b.vertices().to_vec(), triangles: b.triangles().to_vec() })
        .collect();
    Stored { meshes, shapes: records }.serialize(serializer)
}

pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Vec<Shape>, D::Error> {
    let stored = Stored::deserialize(deserializer)?;
    let bases = stored
        .meshes
        .into_iter()
        .map(|m| {
            let mesh =
                TriMesh::new(m.vertices, m.triangles).map_err(|e| D::Error::custom(format!("stored mesh {e}")))?;
            ConvexPolyhedron::new(&mesh).map(Arc::new).map_err(|e| D::Error::custom(format!("stored mesh: {e}")))
        })
        .collect::<Result<Vec<_>, D::Error>>()?;
    stored
        .shapes
        .into_iter()
        .map(|record| {
            Ok(match record {
                ShapeRecord::Sphere { radius } => Shape::Sphere { radius },
                ShapeRecord::Ellipsoid { semi_axes } => Shape::Ellipsoid { semi_axes },
                ShapeRecord::Bonded(b) => Shape::Bonded(b),
                ShapeRecord::Polyhedron { mesh, scale } => {
                    let base = bases.get(mesh as usize).ok_or_else(|| D::Error::custom("stored grain of no mesh"))?;
                    let grain = Polyhedron::new(base.clone(), scale).map_err(|e| D::Error::custom(e.to_string()))?;
                    Shape::Polyhedron(Box::new(grain))
                }
            })
        })
        .collect()
}
