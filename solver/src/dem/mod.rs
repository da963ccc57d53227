//! The discrete element method engine of §3.1: rigid bodies, the linear spring-dashpot contact
//! law, linked-cell neighbour search, exact narrow phase, and semi-implicit Euler integration.

pub mod body;
pub mod contact;
pub mod contact_law;
pub mod domain;
pub mod material;
pub mod neighbours;
pub mod shape;
pub mod simulation;

pub use body::{Bodies, NewBody, uniform_rotation};
pub use contact::{ContactGeometry, ContactPoint};
pub use contact_law::{Calibration, ContactHistory, LinearSpringDashpot};
pub use domain::Domain;
pub use material::Material;
pub use shape::Shape;
pub use simulation::{Audit, MIN_STEPS_PER_COLLISION, Memory, Settings, Shaking, Simulation, StageTimes};
