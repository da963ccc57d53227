//! Where values cross from one stage to the next, each conversion in one place: a planned job
//! into the store's new job, a packing's result into store rows, and store rows into the
//! analysis's records.

use std::collections::BTreeMap;

use analysis::{CampaignSummary, Experiment, JobRecord};
use anyhow::Context;
use solver::packing::PackingResult;
use solver::porosity::ProfilePoint;
use store::{CampaignStatus, ExportRow, GrainStatistic, JobResult, NewJob};

use crate::campaign::PlannedJob;
use crate::stored;

/// A planned job as the store keeps it: the stored spec and, in typed columns, what later
/// stages read without decoding the spec.
pub fn new_job(job: &PlannedJob) -> NewJob {
    let experiment = job.spec.experiment;
    NewJob {
        id: job.id.clone(),
        format: stored::FORMAT,
        spec: stored::encode(&job.spec),
        seed: job.spec.packing.seed,
        parameters: job.parameters.clone(),
        experiment_porosity: experiment.map(|e| e.porosity),
        experiment_std: experiment.and_then(|e| e.std),
    }
}

/// A finished packing's result row and grain statistics.
pub fn result_rows(result: &PackingResult) -> (JobResult, Vec<GrainStatistic>) {
    let p = &result.porosity;
    let row = JobResult {
        porosity: p.bulk,
        z_minus: p.z_minus,
        z_plus: p.z_plus,
        profile: serde_json::to_value(&p.profile).expect("profile points are two numbers"),
        particles: result.particles as u64,
        simulated_time: result.simulated_time,
        steps: result.steps,
        wall_time: result.wall_time.as_secs_f64(),
        solver_version: solver::VERSION.to_string(),
    };
    let statistics = result
        .statistics
        .iter()
        .map(|s| GrainStatistic { name: s.name.to_string(), mean: s.mean, std: s.std })
        .collect();
    (row, statistics)
}

/// A job as the analysis reads it; None for a job without a result.
pub fn job_record(row: &ExportRow) -> anyhow::Result<Option<JobRecord>> {
    let Some(result) = &row.result else { return Ok(None) };
    let profile: Vec<ProfilePoint> = serde_json::from_value(result.profile.clone())
        .with_context(|| format!("job {}: the stored porosity profile is not [{{z, n}}, …]", row.job_id))?;
    Ok(Some(JobRecord {
        job_id: row.job_id.clone(),
        porosity: result.porosity,
        profile,
        parameters: row.parameters.iter().map(|(k, v)| (k.clone(), v.clone())).collect(),
        grain_statistics: row
            .grain_statistics
            .iter()
            .map(|s| (s.name.clone(), (s.mean, s.std)))
            .collect::<BTreeMap<_, _>>(),
        experiment: row.experiment_porosity.map(|porosity| Experiment { porosity, std: row.experiment_std }),
    }))
}

/// The campaign's counts and time spent, for the report's header.
pub fn campaign_summary(status: &CampaignStatus) -> CampaignSummary {
    CampaignSummary {
        name: status.campaign.clone(),
        pending: status.pending as usize,
        running: status.running as usize,
        done: status.done as usize,
        failed: status.failed as usize,
        total_runtime: status.wall_time_finished,
    }
}

#[cfg(test)]
mod tests {
    use serde_json::json;
    use store::JobState;

    use super::*;

    fn row(profile: serde_json::Value) -> ExportRow {
        ExportRow {
            job_id: "j1".into(),
            state: JobState::Done,
            seed: 1,
            attempts: 1,
            error: None,
            parameters: serde_json::Map::new(),
            experiment_porosity: Some(0.4),
            experiment_std: None,
            result: Some(JobResult {
                porosity: 0.38,
                z_minus: 0.003,
                z_plus: 0.02,
                profile,
                particles: 80,
                simulated_time: 0.3,
                steps: 60_000,
                wall_time: 1.0,
                solver_version: "0.1.0".into(),
            }),
            grain_statistics: vec![GrainStatistic { name: "FL".into(), mean: 0.6, std: 0.05 }],
        }
    }

    #[test]
    fn a_stored_row_becomes_a_record_and_an_unreadable_profile_an_error() {
        let record = job_record(&row(json!([{"z": 0.0005, "n": 0.5}]))).unwrap().unwrap();
        assert_eq!(record.profile, [ProfilePoint { z: 0.0005, n: 0.5 }]);
        assert_eq!(record.experiment, Some(Experiment { porosity: 0.4, std: None }));
        assert_eq!(record.grain_statistics["FL"], (0.6, 0.05));
        let error = job_record(&row(json!({"z": 1}))).unwrap_err().to_string();
        assert!(error.contains("job j1") && error.contains("porosity profile"), "{error}");
        let pending = ExportRow { result: None, ..row(json!([])) };
        assert_eq!(job_record(&pending).unwrap(), None);
    }
}
