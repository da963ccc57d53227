//! sedpack's solver: grains, the discrete element method engine, the packing protocol of
//! Rettinger et al. (2022) and the porosity evaluation. It knows nothing of files of campaigns
//! or databases; the pipeline crate feeds it typed specifications.

pub mod grain;
