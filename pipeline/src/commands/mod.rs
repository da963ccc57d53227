//! One module per command of the command line.

pub mod archive;
pub mod bench;
pub mod campaign;
pub mod forms;
pub mod pack;
pub mod porosity;
pub mod predict;
pub mod report;
pub mod sample;
pub mod settle;
