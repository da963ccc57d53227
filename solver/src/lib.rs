//! sedpack's solver: grains, the discrete element method engine, the packing protocol of
//! Rettinger et al. (2022) and the porosity evaluation. It knows nothing of job files, campaigns
//! or databases; the pipeline crate feeds it typed specifications.

pub mod bed;
pub mod dem;
pub mod fabric;
pub mod fluid;
pub mod grain;
pub mod packing;
pub mod porosity;

use thiserror::Error;

/// Version of the solver, stored with every result.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// Why a simulation stopped without a result.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SolverError {
    #[error(
        "time step {time_step} s is too large for the collision time {collision_time} s: a collision must last at least 10 steps (the paper uses 40)"
    )]
    TimeStepTooLarge { time_step: f64, collision_time: f64 },
    #[error(
        "the periodic domain (width {width} m) must be wider than its longest grain reaches ({reach} m: twice the largest half-length plus the skin); widen domain.width or narrow the form distribution"
    )]
    DomainTooNarrow { width: f64, reach: f64 },
    #[error(
        "unstable simulation at t = {time:.6} s: two grains overlap by {relative:.2} of the smaller one's half-thickness"
    )]
    Overlap { time: f64, relative: f64 },
    #[error("unstable simulation at t = {time:.6} s: a position or velocity is no longer a finite number")]
    NotFinite { time: f64 },
}
