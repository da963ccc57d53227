//! Fluid forces on the grains, after the second paper (Sun & Xiao §2.3–2.4): drag per
//! component sphere by Syamlal et al. with the local fluid fraction (Eqs. 3–7), Saffman lift
//! (Eq. 8), summed into force and torque at the grain; in a prescribed fluid velocity field
//! (still water, a uniform stream, a laminar or logarithmic channel profile over the bed).
//! Buoyancy stays where it was, in the engine's gravity minus buoyancy (Eq. 10 of the first
//! paper), with the same fluid density.
//!
//! Every `coupling` steps, as a stage of [`crate::dem::Simulation::step`] when fluid forces are
//! on: the grains' volumes are spread over a coarse grid for the fluid fraction ([`fraction`]),
//! the bed surface is found where a channel profile needs it, then every body gets its fluid
//! force and torque as a [`FluidResponse`], linear in the body's velocity:
//! - a sphere and each component sphere of a bonded grain: drag (Eqs. 3–7) and lift (Eq. 8) at
//!   its centre, with the velocity of that point of the grain and the fluid fraction at the
//!   grain's centre of mass; a bonded grain's spheres are sheltered by the wakes of the grain's
//!   spheres they touch upstream ([`shielding`], sedpack's model);
//! - an ellipsoid or a polyhedron, which is not made of spheres: Haider & Levenspiel's (1989)
//!   drag curve for its sphericity under the same hindrance, and lift as on the sphere of equal
//!   volume, at its centre, so no torque: such a grain keeps the orientation it has.
//!
//! A CFD–DEM code such as the second paper's (SediFoam: OpenFOAM with LAMMPS) computes the fluid
//! forces once per fluid time step and keeps them over the many DEM steps in between. sedpack
//! keeps, instead of the forces, the drag and lift coefficients and the fluid velocities of the
//! update (both linear in the slip), and every step applies them to the body's velocity of that
//! step (as CFD–DEM codes with a semi-implicit drag do): a grain that starts, stops or bounces
//! between two updates feels the drag of its new velocity at once, and the drag stays stable
//! where its response time in a dense bed is a few steps.

pub mod drag;
pub mod flow;
pub mod fraction;
pub mod lift;
pub mod settling;
pub mod shielding;
pub mod sphericity;

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use self::drag::{FluidProperties, HaiderLevenspiel, Hindrance, SyamlalOBrien};
use self::flow::Flow;
use self::fraction::{FractionGrid, Stencil};
use self::lift::SaffmanLift;
use self::shielding::Wake;
use crate::dem::{Bodies, Domain, Shape};
use crate::porosity;

/// The papers' water: density 1000 kg/m³ (the first paper's §4.2, the second's Table 1) and the
/// dynamic viscosity of water at 20 °C, 1.0016 mPa·s (IAPWS; the second paper's ν = 1.0e-6
/// m²/s rounds it). Water at 20 °C is 998.21 kg/m³, 0.18 % lighter.
pub const WATER: FluidProperties = FluidProperties { density: 1000.0, viscosity: 1.0016e-3 };

/// The fluid forces of a simulation: the fluid's viscosity (its density is the material's
/// `fluid_density`, the same as buoyancy's), the prescribed flow and the averaging.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Fluid {
    /// Dynamic viscosity μ (Pa·s).
    pub viscosity: f64,
    pub flow: Flow,
    /// Saffman lift (Eq. 8) on or off.
    pub lift: bool,
    /// Side of the fluid-fraction grid's cells (m), a few grain sizes.
    pub cell: f64,
    /// Slice height and cut-off porosity of the bed surface of §4.4 (the first paper), from
    /// which channel profiles are measured.
    pub slice: f64,
    pub cutoff: f64,
    /// Time steps from one update of the fluid forces to the next (≥ 1): the fluid time step
    /// of a CFD–DEM code over the DEM's Δt.
    pub coupling: u32,
}

/// A body's fluid force and torque (about its centre of mass) as of the last update, linear in
/// its velocity v and angular velocity ω: f = f₀ − B v + C ω and t = t₀ − E v + G ω. The sum
/// over its spheres j (arm r_j from the centre of mass, fluid velocity U_j) of the drag and
/// lift T_j (U_j − v − ω × r_j), T_j = s_j (β_j I − K_j [ω_f]×): the slip, sheltered by s_j,
/// times the drag coefficient β_j of the update's slip, and Saffman's K_j (w × ω_f). At the
/// update it is the exact force and torque of that step.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct FluidResponse {
    force: Vector3<f64>,
    force_velocity: Matrix3<f64>,
    force_spin: Matrix3<f64>,
    torque: Vector3<f64>,
    torque_velocity: Matrix3<f64>,
    torque_spin: Matrix3<f64>,
}

impl FluidResponse {
    /// Force and torque on the body at velocity `v` and angular velocity `w`.
    #[inline]
    pub fn load(&self, v: &Vector3<f64>, w: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        (
            self.force - self.force_velocity * v + self.force_spin * w,
            self.torque - self.torque_velocity * v + self.torque_spin * w,
        )
    }

    /// Adds a sphere at `arm` seeing fluid velocity `fluid` through the slip map `t`.
    fn add(&mut self, t: &Matrix3<f64>, fluid: &Vector3<f64>, arm: &Vector3<f64>) {
        // w = U − v − ω × r = U − v + [r]× ω.
        let r = arm.cross_matrix();
        let f = t * fluid;
        self.force += f;
        self.force_velocity += t;
        self.force_spin += t * r;
        self.torque += arm.cross(&f);
        self.torque_velocity += r * t;
        self.torque_spin += r * t * r;
    }
}

/// The slip map of one sphere: drag β and lift K (w × ω), both scaled by the shelter s.
fn slip_map(shelter: f64, drag: f64, lift: f64, vorticity: &Vector3<f64>) -> Matrix3<f64> {
    // w × ω = −[ω]× w.
    (Matrix3::identity() * drag - vorticity.cross_matrix() * lift) * shelter
}

/// A sphere of a body as the fluid sees it: the body itself as its sphere of equal volume, or
/// one component sphere of a bonded grain.
#[derive(Debug, Clone, Copy)]
struct Wet {
    center: Vector3<f64>,
    radius: f64,
    volume: f64,
    stencil: Stencil,
}

/// What the fluid stage keeps of a body's shape, worked out once (shapes never change).
#[derive(Debug, Clone)]
struct BodyShape {
    /// Diameter of the sphere of equal volume (m).
    diameter: f64,
    /// The drag curve of a body not made of spheres (ellipsoid, polyhedron).
    curve: Option<HaiderLevenspiel>,
    /// A bonded grain's spheres that touch each other (indices within the grain): the wakes
    /// that shelter a sphere, `touching[start[j]..start[j + 1]]` for sphere j.
    start: Vec<u16>,
    touching: Vec<u16>,
}

impl BodyShape {
    fn of(shape: &Shape) -> Self {
        let curve = matches!(shape, Shape::Ellipsoid { .. } | Shape::Polyhedron(_))
            .then(|| HaiderLevenspiel::new(sphericity::sphericity(shape)));
        let (mut start, mut touching) = (vec![0], Vec::new());
        if let Shape::Bonded(b) = shape {
            // The construction places neighbours exactly in contact; 1 % covers rounding.
            for a in &b.spheres {
                touching.extend(b.spheres.iter().enumerate().filter_map(|(k, c)| {
                    let gap = (a.center - c.center).norm();
                    (gap > 0.0 && gap <= 1.01 * (a.radius + c.radius)).then_some(k as u16)
                }));
                start.push(touching.len() as u16);
            }
        }
        Self { diameter: 2.0 * shape.equivalent_radius(), curve, start, touching }
    }
}

/// The fluid stage's working memory, owned by the step pipeline: filled afresh at every update
/// but for what depends on shapes alone.
#[derive(Debug, Clone, Default)]
pub struct Scratch {
    grid: FractionGrid,
    /// The spheres of every body, body k's at `wet[first[k]..first[k + 1]]`.
    wet: Vec<Wet>,
    first: Vec<usize>,
    shapes: Vec<BodyShape>,
    /// Volume-equivalent spheres (height, radius) for the bed surface.
    spheres: Vec<(f64, f64)>,
    /// Height of the bed surface the profiles are measured from (m).
    pub bed: f64,
}

impl Fluid {
    /// Still water of `viscosity` with lift, averaged over cells of side `cell` and updated
    /// every `coupling` steps (the bed surface's slice and cut-off serve channel flows only).
    pub fn still(viscosity: f64, cell: f64, coupling: u32) -> Self {
        Self { viscosity, flow: Flow::Quiescent, lift: true, cell, slice: cell, cutoff: 0.5, coupling }
    }

    /// The fluid force and torque of every body from this step on, into `responses`.
    pub fn update(
        &self,
        bodies: &Bodies,
        domain: &Domain,
        density: f64,
        scratch: &mut Scratch,
        responses: &mut Vec<FluidResponse>,
    ) {
        let fluid = FluidProperties { density, viscosity: self.viscosity };
        let n = bodies.len();
        for k in scratch.shapes.len()..n {
            scratch.shapes.push(BodyShape::of(&bodies.shape[k]));
        }
        scratch.shapes.truncate(n);

        let top = (0..n).map(|k| bodies.position[k].z + bodies.bounding_radius[k]).fold(0.0, f64::max);
        scratch.grid.reset(domain, self.cell, top);
        scratch.wet.clear();
        scratch.first.clear();
        for k in 0..n {
            scratch.first.push(scratch.wet.len());
            for (center, radius, volume) in pieces(&bodies.shape[k], &bodies.position[k], &bodies.orientation[k]) {
                let stencil = scratch.grid.stencil(&center);
                scratch.grid.deposit(&stencil, volume);
                scratch.wet.push(Wet { center, radius, volume, stencil });
            }
        }
        scratch.first.push(scratch.wet.len());
        scratch.bed = if self.flow.needs_bed() { self.bed_surface(bodies, domain, &mut scratch.spheres) } else { 0.0 };

        let Scratch { grid, shapes, bed, wet, first, .. } = scratch;
        responses.resize(n, FluidResponse::default());
        responses.par_iter_mut().enumerate().for_each(|(k, response)| {
            let wet = &wet[first[k]..first[k + 1]];
            // The fluid fraction the other grains leave, at the centre of mass: the grid
            // averages over cells of several grains, so one value serves all of a grain's spheres.
            let centre = grid.stencil(&bodies.position[k]);
            let own: f64 = wet.iter().map(|w| w.volume * w.stencil.overlap(&centre)).sum();
            let hindrance = Hindrance::new(grid.fluid_fraction(&centre, own));
            *response = match shapes[k].curve {
                Some(curve) => self.single_body(bodies, k, &shapes[k], curve, &hindrance, *bed, &fluid),
                None => self.spheres(bodies, k, wet, &shapes[k], &hindrance, *bed, &fluid),
            };
        });
    }

    /// Haider & Levenspiel's drag and the lift of the sphere of equal volume at the centre.
    #[allow(clippy::too_many_arguments)]
    fn single_body(
        &self,
        bodies: &Bodies,
        k: usize,
        shape: &BodyShape,
        curve: HaiderLevenspiel,
        hindrance: &Hindrance,
        bed: f64,
        fluid: &FluidProperties,
    ) -> FluidResponse {
        let (velocity, vorticity) = self.flow.at(&bodies.position[k], bed, fluid.kinematic_viscosity());
        let speed = (velocity - bodies.velocity[k]).norm();
        let d = shape.diameter;
        let drag = SyamlalOBrien { curve }.coefficient(fluid, d, bodies.volume[k], hindrance, speed);
        let lift = if self.lift { SaffmanLift::PAPER.coefficient(fluid, d, &vorticity) } else { 0.0 };
        let mut response = FluidResponse::default();
        response.add(&slip_map(1.0, drag, lift, &vorticity), &velocity, &Vector3::zeros());
        response
    }

    /// Drag and lift on each sphere of a sphere or bonded grain, summed at the centre of mass.
    #[allow(clippy::too_many_arguments)]
    fn spheres(
        &self,
        bodies: &Bodies,
        k: usize,
        wet: &[Wet],
        shape: &BodyShape,
        hindrance: &Hindrance,
        bed: f64,
        fluid: &FluidProperties,
    ) -> FluidResponse {
        let x = bodies.position[k];
        let nu = fluid.kinematic_viscosity();
        // Fluid velocity and vorticity at a sphere's centre, and the slip there.
        let seen = |w: &Wet| {
            let (velocity, vorticity) = self.flow.at(&w.center, bed, nu);
            (velocity, vorticity, velocity - bodies.point_velocity(k, &(w.center - x)))
        };
        let wake = (wet.len() > 1)
            .then(|| {
                Wake::new(&(wet.iter().map(|w| seen(w).2 * w.volume).sum::<Vector3<f64>>() / bodies.volume[k]), nu)
            })
            .flatten();
        let mut response = FluidResponse::default();
        for (j, w) in wet.iter().enumerate() {
            let (velocity, vorticity, slip) = seen(w);
            let shelter = wake.as_ref().map_or(1.0, |wake| {
                let touching = &shape.touching[shape.start[j] as usize..shape.start[j + 1] as usize];
                wake.shelter(
                    &w.center,
                    w.radius,
                    touching.iter().map(|&i| (wet[i as usize].center, wet[i as usize].radius)),
                )
            });
            let d = 2.0 * w.radius;
            let drag = SyamlalOBrien::SPHERES.coefficient(fluid, d, w.volume, hindrance, shelter * slip.norm());
            let lift = if self.lift { SaffmanLift::PAPER.coefficient(fluid, d, &vorticity) } else { 0.0 };
            response.add(&slip_map(shelter, drag, lift, &vorticity), &velocity, &(w.center - x));
        }
        response
    }

    /// The free surface of §4.4 (first paper) over the bodies as volume-equivalent spheres: the
    /// height where the solid fraction falls through 1 − cut-off from the top down; the floor
    /// while no bed has formed.
    fn bed_surface(&self, bodies: &Bodies, domain: &Domain, spheres: &mut Vec<(f64, f64)>) -> f64 {
        spheres.clear();
        spheres.extend((0..bodies.len()).map(|k| (bodies.position[k].z, bodies.shape[k].equivalent_radius())));
        let fraction = porosity::solid_fractions(spheres, domain.cross_section(), self.slice);
        porosity::surface_index(&fraction, 1.0 - self.cutoff).map_or(0.0, |k| k as f64 * self.slice)
    }
}

/// Centres (world), radii and volumes of the spheres that make a body for the fluid: its
/// component spheres if bonded, else the body itself at its centre as the sphere of equal volume.
fn pieces<'a>(
    shape: &'a Shape,
    x: &'a Vector3<f64>,
    q: &'a UnitQuaternion<f64>,
) -> impl Iterator<Item = (Vector3<f64>, f64, f64)> + 'a {
    let bonded = match shape {
        Shape::Bonded(b) => &b.spheres[..],
        _ => &[],
    };
    let whole = bonded.is_empty().then(|| (*x, shape.equivalent_radius(), shape.volume()));
    whole.into_iter().chain(bonded.iter().map(move |c| (x + q * c.center, c.radius, c.volume())))
}
