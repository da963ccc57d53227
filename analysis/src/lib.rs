//! Porosity models from packing results (§6.3, §7.2 of Rettinger et al. 2022). The analysis
//! reads feature tables by column name; it knows nothing of the DEM or of SQLite.

pub mod model;
pub mod paper;

pub use model::{CrossValidation, LinearModel, ModelError};
