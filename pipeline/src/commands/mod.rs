//! One module per command of the command line.

pub mod forms;
pub mod predict;
pub mod sample;
