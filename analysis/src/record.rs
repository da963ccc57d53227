//! What the analysis reads: one plain record per finished job and a campaign summary. The
//! pipeline maps store rows into these; the analysis never sees SQLite types, and of the solver
//! only the porosity profile's points, the imbrication and the sieve classes as drawn.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use solver::fabric::Imbrication;
use solver::grain::DrawnClass;
use solver::porosity::ProfilePoint;

use crate::paper::{ModelPorosity, NearestSetup, PaperPorosity};

/// A measured porosity to compare the simulated one with (Table 6).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Experiment {
    pub porosity: f64,
    /// Standard deviation of the measurement; None when the source does not give it.
    pub std: Option<f64>,
}

/// A finished packing job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JobRecord {
    pub job_id: String,
    /// Bulk porosity (§4.4).
    pub porosity: f64,
    pub profile: Vec<ProfilePoint>,
    /// Grid keys (dotted names, e.g. "grains.form.mu_fl") and seed → value.
    pub parameters: BTreeMap<String, serde_json::Value>,
    /// "FL", "inv_FL", …, "WFI", "inv_WFI" → (number-based mean, std) over the packing's grains.
    pub grain_statistics: BTreeMap<String, (f64, f64)>,
    /// The Table 3 size case of the grains' sieve curve ("U1" … "B70"); None for another curve.
    pub size_case: Option<String>,
    /// Measured porosity, when the campaign gives one.
    pub experiment: Option<Experiment>,
    /// The paper's simulated porosity, when the packing is one of its setups (Tables 5–8, 11).
    pub paper: Option<PaperPorosity>,
    /// When it is none of them: the nearest of the paper's setups and what differs.
    #[serde(default)]
    pub paper_nearest: Option<NearestSetup>,
    /// The paper's porosity model at the grains' measured forms, when the packing is in the
    /// models' setting (Eqs. 17–19, 23–24).
    #[serde(default)]
    pub paper_model: Option<ModelPorosity>,
    /// The fluid forces the packing was deposited with, in words ("drag, still water"); None:
    /// buoyancy only, the first paper's protocol.
    pub fluid: Option<String>,
    /// The long axes' fabric against the flow, for packings that report one.
    pub imbrication: Option<Imbrication>,
    /// Grains and mass created per sieve class, against the curve's fractions; empty for
    /// results stored before sedpack recorded them.
    #[serde(default)]
    pub size_classes: Vec<DrawnClass>,
    /// The packing's setup in words, item → value (domain, grains, sieve curve, mass, shaking,
    /// contact point…), for the report's setup table.
    pub setup: Vec<(String, String)>,
    /// What the packing took.
    pub cost: Cost,
}

/// What a packing took: its grains, the time it simulated and the wall time it stepped for.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Cost {
    pub grains: u64,
    /// s.
    pub simulated_time: f64,
    /// s, summed over the attempts it was resumed in.
    pub wall_time: f64,
}

/// The campaign as a whole, for the report header.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CampaignSummary {
    pub name: String,
    pub pending: usize,
    pub running: usize,
    pub done: usize,
    pub failed: usize,
    /// Runtimes of the finished jobs added up, s.
    pub total_runtime: f64,
    /// Finished jobs whose grains were created by a sedpack that dropped the grains finding no
    /// room on the generation grid (0.1.0), which biased their size and form distributions.
    pub dropped_grains: usize,
}

impl CampaignSummary {
    pub fn jobs(&self) -> usize {
        self.pending + self.running + self.done + self.failed
    }
}
