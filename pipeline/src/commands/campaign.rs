//! `sedpack run`, `resume`, `status` and `export`: campaigns in the SQLite store.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Duration;

use analysis::csv;
use anyhow::{Context, bail};
use serde::Serialize;
use serde_json::{Map, Value};
use store::{CampaignStatus, ExportRow, NewJob, Store};

use crate::campaign::read_campaign;
use crate::cli::{ExportArgs, ResumeArgs, RunArgs, StatusArgs};
use crate::outln;
use crate::output::{Table, print_json};
use crate::records::new_job;
use crate::runner::{self, RunOptions, Summary};

pub(crate) fn runtime() -> anyhow::Result<tokio::runtime::Runtime> {
    Ok(tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?)
}

/// Opens an existing database; status, export and resume never create one.
pub(crate) async fn open_existing(db: &Path) -> anyhow::Result<Store> {
    if !db.exists() {
        bail!("{}: no such database (start a campaign with `sedpack run CAMPAIGN.yaml`)", db.display());
    }
    Ok(Store::open(db).await?)
}

/// Logs go to a file beside the database: DB with the extension `.log`.
fn start_log(db: &Path) -> anyhow::Result<PathBuf> {
    let path = db.with_extension("log");
    let file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .with_context(|| format!("{}", path.display()))?;
    // A second initialisation (tests calling `run` twice in one process) keeps the first log.
    let _ = tracing_subscriber::fmt().with_writer(std::sync::Mutex::new(file)).with_ansi(false).try_init();
    Ok(path)
}

fn workers(requested: Option<usize>) -> anyhow::Result<usize> {
    match requested {
        Some(0) => bail!("--workers must be at least 1"),
        Some(n) => Ok(n),
        None => Ok(std::thread::available_parallelism().map_or(1, |n| n.get())),
    }
}

fn report(name: &str, summary: Summary, status: &CampaignStatus) -> std::io::Result<()> {
    outln!(
        "{name}: {} job(s) finished now, {} failed now; campaign: {} done, {} failed, {} pending, {} running",
        summary.completed,
        summary.failed,
        status.done,
        status.failed,
        status.pending,
        status.running
    )?;
    for f in &status.failures {
        outln!("  failed {}: {}", f.job_id, f.error)?;
    }
    if summary.interrupted {
        outln!("interrupted: run `sedpack resume {name}` to finish the campaign")?;
    }
    Ok(())
}

/// `--checkpoint-interval` as a duration: a positive, finite number of seconds.
fn checkpoint_interval(seconds: f64) -> anyhow::Result<Duration> {
    Duration::try_from_secs_f64(seconds)
        .ok()
        .filter(|d| !d.is_zero())
        .ok_or_else(|| anyhow::anyhow!("--checkpoint-interval: expected a positive number of seconds, got {seconds}"))
}

pub fn run(args: &RunArgs) -> anyhow::Result<()> {
    let options = RunOptions {
        workers: workers(args.workers)?,
        checkpoint_interval: checkpoint_interval(args.checkpoint_interval)?,
    };
    let campaign = read_campaign(&args.campaign)?;
    let log = start_log(&args.db)?;
    runtime()?.block_on(async {
        let store = Store::open(&args.db).await?;
        store.upsert_campaign(&campaign.name, &campaign.text).await?;
        let jobs: Vec<NewJob> = campaign.jobs.iter().map(new_job).collect();
        let new = store.add_jobs(&campaign.name, &jobs).await?;
        if args.retry_failed {
            let retried = store.requeue_failed(&campaign.name).await?;
            outln!("{}: {retried} failed job(s) returned to pending", campaign.name)?;
        }
        outln!(
            "{}: {} job(s), {new} new; database {}, log {}",
            campaign.name,
            jobs.len(),
            args.db.display(),
            log.display()
        )?;
        let summary = runner::run(&store, &campaign.name, &options, !args.quiet).await?;
        report(&campaign.name, summary, &store.status(&campaign.name).await?)?;
        Ok(())
    })
}

pub fn resume(args: &ResumeArgs) -> anyhow::Result<()> {
    let options = RunOptions {
        workers: workers(args.workers)?,
        checkpoint_interval: checkpoint_interval(args.checkpoint_interval)?,
    };
    runtime()?.block_on(async {
        let store = open_existing(&args.db).await?;
        store.campaign(&args.name).await?;
        start_log(&args.db)?;
        let summary = runner::run(&store, &args.name, &options, !args.quiet).await?;
        report(&args.name, summary, &store.status(&args.name).await?)?;
        Ok(())
    })
}

#[derive(Serialize)]
struct StatusRecord {
    #[serde(flatten)]
    status: CampaignStatus,
    /// Pending and running jobs times the mean wall time of a finished job, for one worker (s).
    estimated_time_left: Option<f64>,
}

fn status_record(status: CampaignStatus) -> StatusRecord {
    let left = status.mean_wall_time_done.map(|m| m * (status.pending + status.running) as f64);
    StatusRecord { status, estimated_time_left: left }
}

pub fn status(args: &StatusArgs) -> anyhow::Result<()> {
    runtime()?.block_on(async {
        let store = open_existing(&args.db).await?;
        let names: Vec<String> = match &args.name {
            Some(name) => vec![store.campaign(name).await?.name],
            None => store.campaigns().await?.into_iter().map(|c| c.name).collect(),
        };
        let mut records = Vec::new();
        for name in &names {
            records.push(status_record(store.status(name).await?));
        }
        if args.json {
            // One object for a named campaign, a list of every campaign otherwise.
            return match (&args.name, records.as_slice()) {
                (Some(_), [record]) => print_json(record),
                _ => print_json(&records),
            };
        }
        if records.is_empty() {
            outln!("no campaigns in {}", args.db.display())?;
        }
        for r in &records {
            let s = &r.status;
            let mut table = Table::default();
            table
                .row("campaign", s.campaign.clone())
                .row(
                    "jobs",
                    format!(
                        "{} ({} done, {} failed, {} running, {} pending)",
                        s.jobs, s.done, s.failed, s.running, s.pending
                    ),
                )
                .row("time spent", format!("{:.0} s on finished jobs", s.wall_time_finished));
            if let Some(left) = r.estimated_time_left {
                table.row("time left", format!("≈ {left:.0} s for one worker"));
            }
            for f in &s.failures {
                table.row(format!("failed {}", f.job_id), f.error.clone());
            }
            table.print()?;
        }
        Ok(())
    })
}

pub fn export(args: &ExportArgs) -> anyhow::Result<()> {
    let rows = runtime()?.block_on(async {
        let store = open_existing(&args.db).await?;
        store.campaign(&args.name).await?;
        Ok::<_, anyhow::Error>(store.export(&args.name).await?)
    })?;
    let mut out: Box<dyn Write> = match &args.out {
        Some(path) => Box::new(std::fs::File::create(path).with_context(|| format!("{}", path.display()))?),
        None => Box::new(std::io::stdout().lock()),
    };
    write_csv(&mut out, &rows)?;
    out.flush()?;
    Ok(())
}

/// One row per job: id, state, seed, the grid keys, the result and the grain statistics.
fn write_csv(out: &mut impl Write, rows: &[ExportRow]) -> anyhow::Result<()> {
    let mut keys: Vec<String> = Vec::new();
    for row in rows {
        for key in row.parameters.keys() {
            if key != "seed" && !keys.contains(key) {
                keys.push(key.clone());
            }
        }
    }
    let statistics = solver::grain::feature_names();
    let mut header = vec!["job_id".to_string(), "state".into(), "seed".into()];
    header.extend(keys.iter().cloned());
    header.extend(["porosity", "z_minus", "z_plus", "particles", "simulated_time", "wall_time"].map(String::from));
    for name in &statistics {
        header.push(format!("mean_{name}"));
        header.push(format!("std_{name}"));
    }
    writeln!(out, "{}", header.iter().map(|h| csv::field(h)).collect::<Vec<_>>().join(","))?;
    for row in rows {
        let mut fields = vec![row.job_id.clone(), row.state.as_str().to_string(), row.seed.to_string()];
        fields.extend(keys.iter().map(|k| csv_value(row.parameters.get(k))));
        match &row.result {
            Some(r) => fields.extend(
                [r.porosity, r.z_minus, r.z_plus, r.particles as f64, r.simulated_time, r.wall_time]
                    .map(|v| v.to_string()),
            ),
            None => fields.extend(std::iter::repeat_n(String::new(), 6)),
        }
        let by_name: Map<String, Value> =
            row.grain_statistics.iter().map(|s| (s.name.clone(), serde_json::json!([s.mean, s.std]))).collect();
        for name in &statistics {
            match by_name.get(name) {
                Some(v) => {
                    fields.push(v[0].to_string());
                    fields.push(v[1].to_string());
                }
                None => fields.extend([String::new(), String::new()]),
            }
        }
        writeln!(out, "{}", fields.join(","))?;
    }
    Ok(())
}

/// A grid value as a CSV field: a string as its text, anything else as its JSON.
fn csv_value(value: Option<&Value>) -> String {
    match value {
        None | Some(Value::Null) => String::new(),
        Some(Value::String(s)) => csv::field(s),
        Some(other) => csv::field(&other.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use serde_json::json;

    use super::*;

    #[test]
    fn grid_values_become_csv_fields() {
        assert_eq!(csv_value(Some(&json!(0.4))), "0.4");
        assert_eq!(csv_value(Some(&json!("U7"))), "U7");
        assert_eq!(csv_value(Some(&json!("a,b"))), "\"a,b\"");
        assert_eq!(csv_value(Some(&json!({"fl": 0.5, "el": 0.6}))), r#""{""fl"":0.5,""el"":0.6}""#);
        assert_eq!(csv_value(None), "");
    }
}
