//! `sedpack report NAME --out DIR`: the campaign's porosity models and report (§6.3, §7.2).

use std::collections::BTreeMap;

use analysis::record::{CampaignSummary, JobRecord, ProfilePoint};
use analysis::report::write_report;
use analysis::selection::SelectionOptions;
use anyhow::bail;
use store::{ExportRow, Store};

use crate::cli::ReportArgs;
use crate::commands::campaign::{open_existing, runtime};
use crate::stored;

/// A finished job as the analysis reads it; None for jobs without a result.
fn record(row: &ExportRow) -> Option<JobRecord> {
    let result = row.result.as_ref()?;
    // The measured porosity travels in the job's resolved spec.
    let experiment = stored::decode(stored::FORMAT, &row.spec)
        .ok()
        .and_then(|spec| spec.experiment)
        .map(|e| (e.porosity, e.std.unwrap_or(0.0)));
    Some(JobRecord {
        job_id: row.job_id.clone(),
        porosity: result.porosity,
        profile: result.profile.iter().map(|p| ProfilePoint { z: p.z, n: p.n }).collect(),
        parameters: row.parameters.iter().map(|(k, v)| (k.clone(), v.clone())).collect(),
        grain_statistics: row
            .grain_statistics
            .iter()
            .map(|s| (s.name.clone(), (s.mean, s.std)))
            .collect::<BTreeMap<_, _>>(),
        experiment,
    })
}

pub fn run(args: &ReportArgs) -> anyhow::Result<()> {
    if !(args.threshold > 0.0 && args.threshold <= 1.0) {
        bail!("--threshold = {} is out of range: expected |r| in (0, 1]", args.threshold);
    }
    if args.folds < 2 {
        bail!("--folds = {} is out of range: cross-validation needs at least 2 folds", args.folds);
    }
    let (status, rows) = runtime()?.block_on(async {
        let store: Store = open_existing(&args.db).await?;
        store.campaign(&args.name).await?;
        Ok::<_, anyhow::Error>((store.status(&args.name).await?, store.export(&args.name).await?))
    })?;
    let records: Vec<JobRecord> = rows.iter().filter_map(record).collect();
    let summary = CampaignSummary {
        name: args.name.clone(),
        pending: status.pending as usize,
        running: status.running as usize,
        done: status.done as usize,
        failed: status.failed as usize,
        total_runtime: status.wall_time_finished,
    };
    let options = SelectionOptions { threshold: args.threshold, folds: args.folds, seed: args.seed };
    let files = write_report(&summary, &records, &options, &args.out)?;
    println!("{}: report of {} finished job(s)", args.name, records.len());
    println!("  {}", files.html.display());
    println!("  {}", files.markdown.display());
    println!("  {}", files.dataset.display());
    for model in &files.models {
        println!("  {}", model.display());
    }
    Ok(())
}
