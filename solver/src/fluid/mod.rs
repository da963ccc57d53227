//! Fluid forces on the grains, after the second paper (Sun & Xiao §2.3–2.4): drag per
//! component sphere by Syamlal et al. with the local fluid fraction (Eqs. 3–7), Saffman lift
//! (Eq. 8), summed into force and torque at the grain; in a prescribed fluid velocity field
//! (still water, a uniform stream, a laminar or logarithmic channel profile over the bed).
//! Buoyancy stays where it was, in the engine's gravity minus buoyancy (Eq. 10 of the first
//! paper), with the same fluid density.
//!
//! Per step, as a stage of [`crate::dem::Simulation::step`] when fluid forces are on: the
//! grains' volumes are spread over a coarse grid for the fluid fraction ([`fraction`]), the bed
//! surface is found where a channel profile needs it, then every body gets its fluid force and
//! torque:
//! - a sphere and each component sphere of a bonded grain: drag (Eqs. 3–7) and lift (Eq. 8) at
//!   its centre, with the velocity of that point of the grain and the fluid fraction at the
//!   grain's centre of mass; a bonded grain's spheres are sheltered by the wakes of the grain's
//!   spheres they touch upstream ([`shielding`], sedpack's model);
//! - an ellipsoid or a polyhedron, which is not made of spheres: Haider & Levenspiel's (1989)
//!   drag curve for its sphericity under the same hindrance, and lift as on the sphere of equal
//!   volume, at its centre, so no torque: such a grain keeps the orientation it has.

pub mod drag;
pub mod flow;
pub mod fraction;
pub mod lift;
pub mod settling;
pub mod shielding;
pub mod sphericity;

use nalgebra::{UnitQuaternion, Vector3};
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
}

/// A body's fluid force and torque (about its centre of mass) of one step.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FluidLoad {
    pub force: Vector3<f64>,
    pub torque: Vector3<f64>,
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

/// The fluid stage's working memory, owned by the step pipeline: filled afresh every step but
/// for what depends on shapes alone.
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
    /// This step's fluid force and torque of each body.
    pub loads: Vec<FluidLoad>,
}

impl Fluid {
    /// The fluid forces on every body this step, into `scratch.loads`.
    pub fn apply(&self, bodies: &Bodies, domain: &Domain, density: f64, scratch: &mut Scratch) {
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

        let Scratch { grid, shapes, bed, wet, first, loads, .. } = scratch;
        loads.resize(n, FluidLoad::default());
        loads.par_iter_mut().enumerate().for_each(|(k, load)| {
            let wet = &wet[first[k]..first[k + 1]];
            // The fluid fraction the other grains leave, at the centre of mass: the grid
            // averages over cells of several grains, so one value serves all of a grain's spheres.
            let centre = grid.stencil(&bodies.position[k]);
            let own: f64 = wet.iter().map(|w| w.volume * w.stencil.overlap(&centre)).sum();
            let hindrance = Hindrance::new(grid.fluid_fraction(&centre, own));
            *load = match shapes[k].curve {
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
    ) -> FluidLoad {
        let (velocity, vorticity) = self.flow.at(&bodies.position[k], bed, fluid.kinematic_viscosity());
        let slip = velocity - bodies.velocity[k];
        let d = shape.diameter;
        let mut force = SyamlalOBrien { curve }.force(fluid, d, bodies.volume[k], hindrance, &slip);
        if self.lift {
            force += SaffmanLift::PAPER.force(fluid, d, &slip, &vorticity);
        }
        FluidLoad { force, torque: Vector3::zeros() }
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
    ) -> FluidLoad {
        let x = bodies.position[k];
        let nu = fluid.kinematic_viscosity();
        // Fluid velocity minus the grain's velocity at a sphere's centre, and the vorticity there.
        let seen = |w: &Wet| {
            let (velocity, vorticity) = self.flow.at(&w.center, bed, nu);
            (velocity - bodies.point_velocity(k, &(w.center - x)), vorticity)
        };
        let wake = (wet.len() > 1)
            .then(|| {
                Wake::new(&(wet.iter().map(|w| seen(w).0 * w.volume).sum::<Vector3<f64>>() / bodies.volume[k]), nu)
            })
            .flatten();
        let mut load = FluidLoad::default();
        for (j, w) in wet.iter().enumerate() {
            let (mut slip, vorticity) = seen(w);
            if let Some(wake) = &wake {
                let touching = &shape.touching[shape.start[j] as usize..shape.start[j + 1] as usize];
                slip *= wake.shelter(
                    &w.center,
                    w.radius,
                    touching.iter().map(|&i| (wet[i as usize].center, wet[i as usize].radius)),
                );
            }
            let d = 2.0 * w.radius;
            let mut f = SyamlalOBrien::SPHERES.force(fluid, d, w.volume, hindrance, &slip);
            if self.lift {
                f += SaffmanLift::PAPER.force(fluid, d, &slip, &vorticity);
            }
            load.force += f;
            load.torque += (w.center - x).cross(&f);
        }
        load
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
