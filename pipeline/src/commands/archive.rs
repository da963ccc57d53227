//! `sedpack export --format jsonl` and `sedpack import`: a campaign's done jobs carried whole
//! from one database to another, so that the seeds of a study run on several machines (or on
//! machines that are gone) can be reported together.
//!
//! The file is JSON Lines: a header (`sedpack_results`, the layout's version; the sedpack that
//! wrote it; the campaign and its file), then one done job per line, as [`ArchivedJob`].

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde::{Deserialize, Serialize};
use store::{ArchivedJob, Campaign, Imported, Store};

use crate::cli::ImportArgs;
use crate::commands::campaign::runtime;
use crate::{outln, stored};

/// The layout of the files this version writes and reads.
const LAYOUT: u32 = 1;

/// The first line of a results file.
#[derive(Debug, Serialize, Deserialize)]
struct Header {
    sedpack_results: u32,
    /// The version of sedpack that wrote the file.
    sedpack: String,
    campaign: String,
    /// The campaign file as last submitted to the database the jobs come from.
    campaign_file: String,
}

/// A results file read and checked, ready for [`Store::import`].
struct Results {
    path: PathBuf,
    header: Header,
    jobs: Vec<ArchivedJob>,
}

/// Writes the campaign's header line and one line per done job.
pub fn write(out: &mut impl Write, campaign: &Campaign, jobs: &[ArchivedJob]) -> anyhow::Result<()> {
    let header = Header {
        sedpack_results: LAYOUT,
        sedpack: solver::VERSION.to_string(),
        campaign: campaign.name.clone(),
        campaign_file: campaign.spec.clone(),
    };
    writeln!(out, "{}", serde_json::to_string(&header)?)?;
    for job in jobs {
        writeln!(out, "{}", serde_json::to_string(job)?)?;
    }
    Ok(())
}

pub fn import(args: &ImportArgs) -> anyhow::Result<()> {
    // Every file is read and checked before the database is touched.
    let files = args.files.iter().map(|path| read(path)).collect::<anyhow::Result<Vec<_>>>()?;
    runtime()?.block_on(async {
        let store = Store::open(&args.db).await?;
        for file in &files {
            let imported = store
                .import(&file.header.campaign, &file.header.campaign_file, &file.jobs)
                .await
                .with_context(|| format!("{}: nothing of it was imported", file.path.display()))?;
            outln!("{}: {}", file.path.display(), summary(&file.header.campaign, file.jobs.len(), &imported))?;
        }
        store.close().await;
        Ok(())
    })
}

fn summary(campaign: &str, jobs: usize, imported: &Imported) -> String {
    let mut text = format!(
        "campaign {campaign}, {jobs} done job(s): {} added, {} completed (pending or failed here), {} already done \
         here (kept)",
        imported.added, imported.completed, imported.kept
    );
    if !imported.running.is_empty() {
        text += &format!(
            ", {} running here (left to their worker: {})",
            imported.running.len(),
            imported.running.join(", ")
        );
    }
    text
}

/// Reads a results file and checks each job against its own spec: the spec decodes, hashes to the
/// job's id, and belongs to the header's campaign.
fn read(path: &Path) -> anyhow::Result<Results> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    let mut lines = text.lines().enumerate().filter(|(_, line)| !line.trim().is_empty());
    let not_results = || {
        format!(
            "{}: not a results file of sedpack: its first line should be the header that `sedpack export \
             --format jsonl` writes, with the key `sedpack_results`",
            path.display()
        )
    };
    let (_, first) = lines.next().with_context(not_results)?;
    let value: serde_json::Value = serde_json::from_str(first).with_context(not_results)?;
    let layout = value.get("sedpack_results").and_then(serde_json::Value::as_u64).with_context(not_results)?;
    if layout != u64::from(LAYOUT) {
        let by = value.get("sedpack").and_then(serde_json::Value::as_str).unwrap_or("an unknown version");
        bail!(
            "{}: results layout {layout} (written by sedpack {by}), which this version of sedpack (layout {LAYOUT}) \
             cannot read",
            path.display()
        );
    }
    let header: Header =
        serde_path_to_error::deserialize(value).with_context(|| format!("{}: line 1, the header", path.display()))?;
    let mut jobs = Vec::new();
    for (index, line) in lines {
        let at = || format!("{}: line {}", path.display(), index + 1);
        let mut deserializer = serde_json::Deserializer::from_str(line);
        let job: ArchivedJob = serde_path_to_error::deserialize(&mut deserializer).with_context(at)?;
        check(&job, &header.campaign).with_context(|| format!("{}, job {}", at(), job.job.id))?;
        jobs.push(job);
    }
    Ok(Results { path: path.to_path_buf(), header, jobs })
}

fn check(job: &ArchivedJob, campaign: &str) -> anyhow::Result<()> {
    let spec = stored::decode(job.job.format, &job.job.spec)?;
    if spec.name != campaign {
        bail!("the job is of campaign {:?}, the file's header of {campaign:?}", spec.name);
    }
    let id = stored::job_id(&spec);
    if id != job.job.id {
        bail!("its spec hashes to the id {id}: the line was edited after `sedpack export` wrote it");
    }
    if spec.packing.seed != job.job.seed {
        bail!("its seed is {}, its spec's {}", job.job.seed, spec.packing.seed);
    }
    let porosity = job.result.porosity;
    if !(porosity > 0.0 && porosity < 1.0) {
        bail!("its porosity {porosity} is not in (0, 1)");
    }
    Ok(())
}
