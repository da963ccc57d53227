//! Meshes, settings and packing specs shared by the solver's tests.
#![allow(dead_code)]

use nalgebra::Vector3;
use solver::dem::shape::Polyhedron;
use solver::dem::{Calibration, ContactPoint, Domain, Material, Settings, Shape, Simulation};
use solver::grain::{SieveCurve, TriMesh};
use solver::packing::{DomainKind, PackingSpec, ShapeKind};

/// An axis-aligned box with sides (a, b, c) centred at the origin, outward normals, as
/// (vertices, triangles).
pub fn box_mesh(a: f64, b: f64, c: f64) -> (Vec<Vector3<f64>>, Vec<[u32; 3]>) {
    let mut vertices = Vec::new();
    for k in 0..8 {
        let s = |bit: u32| if k & (1 << bit) != 0 { 0.5 } else { -0.5 };
        vertices.push(Vector3::new(s(0) * a, s(1) * b, s(2) * c));
    }
    // Vertex k has x from bit 0, y from bit 1, z from bit 2; each face as two CCW triangles.
    let faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let mut triangles = Vec::new();
    for f in faces {
        triangles.push([f[0], f[1], f[2]]);
        triangles.push([f[0], f[2], f[3]]);
    }
    (vertices, triangles)
}

/// The box of [`box_mesh`] as a polyhedron grain.
pub fn box_shape(a: f64, b: f64, c: f64) -> Shape {
    let (v, t) = box_mesh(a, b, c);
    Shape::Polyhedron(Box::new(Polyhedron::from_mesh(&TriMesh::new(v, t).unwrap()).unwrap()))
}

/// A UV tessellation of the ellipsoid with semi-axes (a, b, c): `rings` latitude bands and
/// `2·rings` meridians, vertices on the surface.
pub fn ellipsoid_mesh(a: f64, b: f64, c: f64, rings: usize) -> (Vec<Vector3<f64>>, Vec<[u32; 3]>) {
    let sectors = 2 * rings;
    let mut vertices = vec![Vector3::new(0.0, 0.0, c)];
    for r in 1..rings {
        let theta = std::f64::consts::PI * r as f64 / rings as f64;
        for s in 0..sectors {
            let phi = 2.0 * std::f64::consts::PI * s as f64 / sectors as f64;
            vertices.push(Vector3::new(a * theta.sin() * phi.cos(), b * theta.sin() * phi.sin(), c * theta.cos()));
        }
    }
    vertices.push(Vector3::new(0.0, 0.0, -c));
    let south = (vertices.len() - 1) as u32;
    let at = |r: usize, s: usize| (1 + (r - 1) * sectors + s % sectors) as u32;
    let mut triangles = Vec::new();
    for s in 0..sectors {
        triangles.push([0, at(1, s), at(1, s + 1)]);
        triangles.push([south, at(rings - 1, s + 1), at(rings - 1, s)]);
    }
    for r in 1..rings - 1 {
        for s in 0..sectors {
            triangles.push([at(r, s), at(r + 1, s), at(r + 1, s + 1)]);
            triangles.push([at(r, s), at(r + 1, s + 1), at(r, s + 1)]);
        }
    }
    (vertices, triangles)
}

pub fn rhine_mesh_path(k: usize) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("meshes/rhine_scan_{k}.obj"))
}

/// The paper's material and time step (§4.2) with the given restitution, friction and gravity
/// (gravity tilted for slopes), a 1 mm skin and the discrete calibration.
pub fn settings(restitution: f64, friction: f64, gravity: Vector3<f64>) -> Settings {
    let material = Material { restitution, friction, gravity, ..Material::default() };
    Settings {
        material,
        time_step: 5e-6,
        skin: 1e-3,
        calibration: Calibration::Discrete,
        contact_point: ContactPoint::CentreOfPressure,
    }
}

/// A bed of 5.6–8 mm grains in a 4 cm periodic square 15 cm high, given a generation spacing
/// and a shaking duration, with 5 s of simulated time to settle; the paper's setup otherwise.
pub fn small_bed(shape: ShapeKind, mass: f64, spacing: f64, shaking_duration: f64) -> PackingSpec {
    let mut spec = PackingSpec::paper(DomainKind::Periodic);
    spec.domain = Domain::Periodic { width: 0.04 };
    spec.height = Some(0.15);
    spec.grains.shape = shape;
    spec.grains.size = SieveCurve::new(vec![5.6e-3, 8e-3], vec![1.0]).unwrap();
    spec.grains.mass = mass;
    spec.process.spacing = Some(spacing);
    spec.process.shaking_duration = shaking_duration;
    spec.process.max_time = Some(5.0);
    spec
}

/// [`small_bed`] with 5 cm of shaking, these grains' forms and meshes, a 4 mm trim and seed 3.
pub fn small_bed_of(
    shape: ShapeKind,
    form: solver::packing::FormSpec,
    meshes: Option<solver::grain::MeshLibrary>,
    mass: f64,
) -> PackingSpec {
    let mut spec = small_bed(shape, mass, 0.012, 0.05);
    spec.grains.form = form;
    spec.grains.meshes = meshes;
    spec.trim = Some(4e-3);
    spec.seed = 3;
    spec
}

/// Steps until the bodies have separated after their first contact; returns the contact steps.
pub fn collide(sim: &mut Simulation) -> u64 {
    let (mut steps, mut touched) = (0, false);
    for _ in 0..100_000 {
        sim.step().unwrap();
        if sim.contacts > 0 {
            touched = true;
            steps += 1;
        } else if touched {
            return steps;
        }
    }
    panic!("the bodies never met");
}

/// Steps for `time` s; returns body 0's displacement along x and its acceleration from
/// x = x₀ + v₀ t + a t²/2.
pub fn slide_x(sim: &mut Simulation, time: f64) -> (f64, f64) {
    let (x0, v0) = (sim.bodies.position[0].x, sim.bodies.velocity[0].x);
    let n = (time / sim.settings.time_step) as usize;
    for _ in 0..n {
        sim.step().unwrap();
    }
    let t = n as f64 * sim.settings.time_step;
    let dx = sim.bodies.position[0].x - x0;
    (dx, 2.0 * (dx - v0 * t) / (t * t))
}

/// Total linear momentum and angular momentum about the origin of all bodies.
pub fn momenta(sim: &solver::dem::Simulation) -> (Vector3<f64>, Vector3<f64>) {
    let b = &sim.bodies;
    let (mut p, mut l) = (Vector3::zeros(), Vector3::zeros());
    for k in 0..b.len() {
        p += b.mass[k] * b.velocity[k];
        l += b.mass[k] * b.position[k].cross(&b.velocity[k]) + b.world_inertia(k) * b.angular_velocity[k];
    }
    (p, l)
}
