//! `sedpack report NAME --out DIR`: the campaign's porosity models and report (§6.3, §7.2).

use analysis::report::write_report;
use analysis::selection::SelectionOptions;
use analysis::{JobRecord, analyse};
use std::collections::HashMap;

use anyhow::{Context, bail};
use store::Store;

use crate::cli::ReportArgs;
use crate::commands::campaign::{catch_up, open_existing, runtime};
use crate::outln;
use crate::records::{campaign_summary, job_record};
use crate::stored;

pub fn run(args: &ReportArgs) -> anyhow::Result<()> {
    if !(args.threshold > 0.0 && args.threshold <= 1.0) {
        bail!("--threshold = {} is out of range: expected |r| in (0, 1]", args.threshold);
    }
    if args.folds < 2 {
        bail!("--folds = {} is out of range: cross-validation needs at least 2 folds", args.folds);
    }
    let (status, rows, jobs) = runtime()?.block_on(async {
        let store: Store = open_existing(&args.db).await?;
        catch_up(&store, &args.db, &args.name).await?;
        Ok::<_, anyhow::Error>((
            store.status(&args.name).await?,
            store.export(&args.name).await?,
            store.jobs(&args.name).await?,
        ))
    })?;
    // Each job's packing: its size case picks the paper's models, its setup the paper's tables.
    let packings = jobs
        .iter()
        .map(|job| {
            let spec = stored::decode(job.format, &job.spec).with_context(|| format!("job {}", job.id))?;
            Ok((job.id.clone(), spec.packing))
        })
        .collect::<anyhow::Result<HashMap<_, _>>>()?;
    let records: Vec<JobRecord> = rows
        .iter()
        .filter_map(|row| job_record(row, packings.get(&row.job_id)).transpose())
        .collect::<Result<_, _>>()?;
    let options = SelectionOptions { threshold: args.threshold, folds: args.folds, seed: args.seed };
    let analysis = analyse(&records, &args.name, &options)?;
    let summary = campaign_summary(&status, &rows);
    if summary.dropped_grains > 0 {
        eprintln!(
            "sedpack: warning: {}: {} finished job(s) were packed by sedpack 0.1.0, whose generation dropped the \
             grains that found no room: wide sieve curves lost most coarse grains and form mixtures some elongated \
             ones, which biases their porosity (one form in one sieve class is barely affected); pack those again \
             with this version, in a new database",
            args.name, summary.dropped_grains
        );
    }
    let files = write_report(&summary, &records, &analysis, &args.out)?;
    outln!("{}: report of {} finished job(s)", args.name, records.len())?;
    outln!("  {}", files.html.display())?;
    outln!("  {}", files.markdown.display())?;
    outln!("  {}", files.dataset.display())?;
    for model in &files.models {
        outln!("  {}", model.display())?;
    }
    Ok(())
}
