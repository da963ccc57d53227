//! `sedpack report NAME --out DIR`: the campaign's porosity models and report (§6.3, §7.2).

use analysis::report::write_report;
use analysis::selection::SelectionOptions;
use analysis::{JobRecord, analyse};
use anyhow::bail;
use store::Store;

use crate::cli::ReportArgs;
use crate::commands::campaign::{catch_up, open_existing, runtime};
use crate::outln;
use crate::records::{campaign_summary, job_record};

pub fn run(args: &ReportArgs) -> anyhow::Result<()> {
    if !(args.threshold > 0.0 && args.threshold <= 1.0) {
        bail!("--threshold = {} is out of range: expected |r| in (0, 1]", args.threshold);
    }
    if args.folds < 2 {
        bail!("--folds = {} is out of range: cross-validation needs at least 2 folds", args.folds);
    }
    let (status, rows) = runtime()?.block_on(async {
        let store: Store = open_existing(&args.db).await?;
        catch_up(&store, &args.db, &args.name).await?;
        Ok::<_, anyhow::Error>((store.status(&args.name).await?, store.export(&args.name).await?))
    })?;
    let records: Vec<JobRecord> =
        rows.iter().filter_map(|row| job_record(row).transpose()).collect::<Result<_, _>>()?;
    let options = SelectionOptions { threshold: args.threshold, folds: args.folds, seed: args.seed };
    let analysis = analyse(&records, &args.name, &options)?;
    let files = write_report(&campaign_summary(&status), &records, &analysis, &args.out)?;
    outln!("{}: report of {} finished job(s)", args.name, records.len())?;
    outln!("  {}", files.html.display())?;
    outln!("  {}", files.markdown.display())?;
    outln!("  {}", files.dataset.display())?;
    for model in &files.models {
        outln!("  {}", model.display())?;
    }
    Ok(())
}
