//! The run directory, beside the database on the file system the compute nodes share: the only
//! place where the submitting side and the tasks meet (tasks never open the database).
//!
//! ```text
//! sedpack.runs/CAMPAIGN/
//!   JOB_ID/job.json        the stored job, written at submission
//!   JOB_ID/checkpoint      the packing so far, replaced atomically
//!   JOB_ID/result.json     the result, written atomically once
//!   JOB_ID/events          one JSON line per task start, stop, failure and end
//!   JOB_ID/progress        the running packing's phase and time
//!   submissions/TOKEN.sh   each submission's batch script and sbatch command
//!   logs/ARRAY_TASK.out    each task's output (Slurm's and sedpack's)
//! ```

use std::fs::{self, File, OpenOptions};
use std::io::{self, Write};
use std::os::unix::fs::FileExt;
use std::path::{Path, PathBuf};

use anyhow::{Context, anyhow, bail};
use serde::{Deserialize, Serialize};
use store::{GrainStatistic, JobResult};

/// What a result file says first, so that another version's file is recognised as such.
pub const RESULT_FORMAT: u32 = 1;

/// The run directory of one campaign.
#[derive(Debug, Clone)]
pub struct RunDir {
    pub path: PathBuf,
}

impl RunDir {
    /// `DB.runs/CAMPAIGN` beside the database `DB.db`, made absolute: tasks read it from anywhere.
    pub fn of(db: &Path, campaign: &str) -> anyhow::Result<RunDir> {
        let db = std::path::absolute(db).with_context(|| format!("{}", db.display()))?;
        Ok(RunDir { path: db.with_extension("runs").join(file_name(campaign)) })
    }

    pub fn job(&self, id: &str) -> JobDir {
        JobDir { path: self.path.join(id) }
    }

    pub fn logs(&self) -> PathBuf {
        self.path.join("logs")
    }

    /// The output file of task `ARRAY_INDEX` (sbatch's `%A_%a`).
    pub fn log(&self, task: &str) -> PathBuf {
        self.logs().join(format!("{task}.out"))
    }

    pub fn submissions(&self) -> PathBuf {
        self.path.join("submissions")
    }
}

/// A name any file system and Slurm take: letters, digits, `.`, `_` and `-`, others as `_`.
pub fn file_name(name: &str) -> String {
    name.chars().map(|c| if c.is_ascii_alphanumeric() || "._-".contains(c) { c } else { '_' }).collect()
}

/// The folder of one job.
#[derive(Debug, Clone)]
pub struct JobDir {
    pub path: PathBuf,
}

/// The job a task runs, as the submitting side wrote it: the stored job with its format.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaskJob {
    pub id: String,
    pub campaign: String,
    pub format: u32,
    pub spec: serde_json::Value,
}

/// A finished packing as a task leaves it for the submitting side.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaskResult {
    pub result_format: u32,
    pub job: String,
    /// The Slurm task that finished it.
    pub task: String,
    /// UNIX seconds: when that task started and when it finished.
    pub started_at: f64,
    pub finished_at: f64,
    pub result: JobResult,
    pub grain_statistics: Vec<GrainStatistic>,
}

/// One line of a job's events file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Event {
    /// The Slurm task, `ARRAY_INDEX`.
    pub task: String,
    /// The submission the task belongs to.
    pub submission: String,
    pub kind: EventKind,
    /// UNIX seconds.
    pub at: f64,
    pub host: String,
    /// Slurm's SLURM_RESTART_COUNT: how often the task was requeued.
    pub restarts: u32,
    /// Why it stopped or failed.
    pub detail: Option<String>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EventKind {
    Started,
    /// Stopped before its time limit, checkpoint written: to be submitted again.
    Stopped,
    /// Stopped by SIGTERM (cancelled, time limit, requeued or preempted), checkpoint written.
    Terminated,
    Failed,
    Done,
}

impl EventKind {
    pub fn name(self) -> &'static str {
        match self {
            EventKind::Started => "started",
            EventKind::Stopped => "stopped",
            EventKind::Terminated => "terminated",
            EventKind::Failed => "failed",
            EventKind::Done => "done",
        }
    }
}

/// The running packing as a task last saw it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaskProgress {
    pub phase: String,
    pub time: f64,
    pub grains: usize,
    pub contacts: usize,
    /// Fraction of the target mass created (absent from the files of sedpack before 0.2.1).
    #[serde(default)]
    pub mass_created: Option<f64>,
    /// While the packing shakes, the simulated time the shaking ends (absent from older files).
    #[serde(default)]
    pub shaking_until: Option<f64>,
}

impl JobDir {
    pub fn job_file(&self) -> PathBuf {
        self.path.join("job.json")
    }

    pub fn checkpoint(&self) -> PathBuf {
        self.path.join("checkpoint")
    }

    pub fn result(&self) -> PathBuf {
        self.path.join("result.json")
    }

    fn events_file(&self) -> PathBuf {
        self.path.join("events")
    }

    pub fn progress_file(&self) -> PathBuf {
        self.path.join("progress")
    }

    /// The job's id: the folder's name.
    pub fn id(&self) -> String {
        self.path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()
    }

    pub fn write_job(&self, job: &TaskJob) -> anyhow::Result<()> {
        fs::create_dir_all(&self.path).with_context(|| format!("{}", self.path.display()))?;
        write_atomically(&self.job_file(), &serde_json::to_vec_pretty(job)?)
    }

    /// The job of this folder; a file that is missing, unreadable or another job's is an error
    /// naming it.
    pub fn read_job(&self) -> anyhow::Result<TaskJob> {
        let path = self.job_file();
        let text = fs::read(&path).map_err(|e| {
            anyhow!(
                "{}: {e}; the run directory must be on a file system that the compute nodes share \
                 with the host that submitted the campaign",
                path.display()
            )
        })?;
        let job: TaskJob = serde_json::from_slice(&text)
            .with_context(|| format!("{}: not a job file of sedpack (truncated?)", path.display()))?;
        if job.id != self.id() {
            bail!("{}: describes job {}, not this folder's job {}", path.display(), job.id, self.id());
        }
        Ok(job)
    }

    pub fn write_result(&self, result: &TaskResult) -> anyhow::Result<()> {
        write_atomically(&self.result(), &serde_json::to_vec(result)?)
    }

    /// The result of this folder's job, None if there is none yet; a file that is not a whole
    /// result of this job is an error saying what is wrong with it.
    pub fn read_result(&self) -> anyhow::Result<Option<TaskResult>> {
        let path = self.result();
        let bytes = match fs::read(&path) {
            Ok(bytes) => bytes,
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(anyhow!("{}: {e}", path.display())),
        };
        #[derive(Deserialize)]
        struct Header {
            result_format: u32,
            job: String,
        }
        let header: Header = serde_json::from_slice(&bytes)
            .map_err(|e| anyhow!("{}: not a whole result file (truncated?): {e}", path.display()))?;
        if header.result_format != RESULT_FORMAT {
            bail!(
                "{}: written by another version of sedpack (result format {}; this version reads {RESULT_FORMAT})",
                path.display(),
                header.result_format
            );
        }
        if header.job != self.id() {
            bail!("{}: the result of job {}, not of this folder's job {}", path.display(), header.job, self.id());
        }
        let result = serde_json::from_slice(&bytes)
            .map_err(|e| anyhow!("{}: not a whole result file (truncated?): {e}", path.display()))?;
        Ok(Some(result))
    }

    /// Moves a result file that cannot be used out of the way, keeping it for inspection; gives
    /// where it went.
    pub fn set_aside_result(&self) -> io::Result<PathBuf> {
        let aside = self.path.join("result.json.rejected");
        fs::rename(self.result(), &aside)?;
        Ok(aside)
    }

    /// Appends an event; only the job's one running task writes here. A line cut short by a
    /// crash is ended first, so that it spoils no other.
    pub fn append_event(&self, event: &Event) -> io::Result<()> {
        let mut file = OpenOptions::new().create(true).read(true).append(true).open(self.events_file())?;
        let length = file.metadata()?.len();
        let mut last = [b'\n'];
        if length > 0 {
            file.read_exact_at(&mut last, length - 1)?;
        }
        let mut line = if last[0] == b'\n' { Vec::new() } else { vec![b'\n'] };
        line.extend(serde_json::to_vec(event).map_err(io::Error::other)?);
        line.push(b'\n');
        file.write_all(&line)?;
        file.sync_data()
    }

    /// The job's events, oldest first; a line cut short by a crash is skipped.
    pub fn events(&self) -> Vec<Event> {
        let text = fs::read_to_string(self.events_file()).unwrap_or_default();
        text.lines().filter_map(|l| serde_json::from_str(l).ok()).collect()
    }

    pub fn write_progress(&self, progress: &TaskProgress) -> io::Result<()> {
        let tmp = self.path.join("progress.tmp");
        fs::write(&tmp, serde_json::to_vec(progress).map_err(io::Error::other)?)?;
        fs::rename(tmp, self.progress_file())
    }

    pub fn progress(&self) -> Option<TaskProgress> {
        serde_json::from_slice(&fs::read(self.progress_file()).ok()?).ok()
    }
}

/// Writes `bytes` to `path` so that a reader sees either the old file or the new one whole,
/// even after a crash: a temporary file in the same folder, fsync, rename, fsync of the folder.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    let folder = path.parent().unwrap_or(Path::new("."));
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = folder.join(format!(".{name}.{}.tmp", std::process::id()));
    let write = || -> io::Result<()> {
        let mut file = File::create(&tmp)?;
        file.write_all(bytes)?;
        file.sync_all()?;
        fs::rename(&tmp, path)?;
        File::open(folder)?.sync_all()
    };
    write().with_context(|| format!("{}: cannot write", path.display()))
}

/// The last `lines` lines of a text file, None if it cannot be read.
pub fn tail(path: &Path, lines: usize) -> Option<String> {
    let text = fs::read(path).ok()?;
    let text = String::from_utf8_lossy(&text);
    let all: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    Some(all[all.len().saturating_sub(lines)..].join(" | "))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn result(job: &str) -> TaskResult {
        TaskResult {
            result_format: RESULT_FORMAT,
            job: job.into(),
            task: "7_0".into(),
            started_at: 1.0,
            finished_at: 2.0,
            result: JobResult {
                porosity: 0.1 + 0.2,
                z_minus: 0.0,
                z_plus: 0.01,
                profile: serde_json::json!([{"z": 0.0005, "n": 0.4}]),
                particles: 60,
                simulated_time: 0.25,
                steps: 50_000,
                wall_time: 0.5,
                solver_version: "0.1.0".into(),
                imbrication: Some(serde_json::json!({"grains": 40, "upstream": 0.6})),
                size_classes: Some(
                    serde_json::json!([{"lower": 0.0056, "upper": 0.008, "asked": 1.0, "grains": 60, "mass": 0.02}]),
                ),
            },
            grain_statistics: vec![GrainStatistic { name: "FL".into(), mean: 1.0, std: 0.0 }],
        }
    }

    #[test]
    fn a_result_reads_back_whole_and_only_as_its_own_job() {
        let dir = tempfile::tempdir().unwrap();
        let job = RunDir { path: dir.path().into() }.job("abc");
        fs::create_dir_all(&job.path).unwrap();
        assert!(job.read_result().unwrap().is_none());
        job.write_result(&result("abc")).unwrap();
        let back = job.read_result().unwrap().unwrap();
        assert_eq!(back, result("abc"));
        assert_eq!(back.result.porosity.to_bits(), (0.1f64 + 0.2).to_bits(), "bit for bit");
        let entries: Vec<_> = fs::read_dir(&job.path).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(entries, ["result.json"], "no temporary file left");

        let bytes = fs::read(job.result()).unwrap();
        fs::write(job.result(), &bytes[..bytes.len() / 2]).unwrap();
        let error = job.read_result().unwrap_err().to_string();
        assert!(error.contains("abc/result.json: not a whole result file (truncated?)"), "{error}");
        job.write_result(&result("other")).unwrap();
        let error = job.read_result().unwrap_err().to_string();
        assert!(error.contains("the result of job other, not of this folder's job abc"), "{error}");
        let aside = job.set_aside_result().unwrap();
        assert!(aside.exists() && !job.result().exists());
    }

    #[test]
    fn a_job_file_names_its_folder_and_a_missing_one_the_shared_file_system() {
        let dir = tempfile::tempdir().unwrap();
        let run = RunDir { path: dir.path().into() };
        let job = TaskJob { id: "abc".into(), campaign: "c".into(), format: 2, spec: serde_json::json!({}) };
        run.job("abc").write_job(&job).unwrap();
        assert_eq!(run.job("abc").read_job().unwrap(), job);
        fs::create_dir_all(&run.job("xyz").path).unwrap();
        fs::copy(run.job("abc").job_file(), run.job("xyz").job_file()).unwrap();
        assert!(
            run.job("xyz").read_job().unwrap_err().to_string().contains("describes job abc, not this folder's job xyz")
        );
        let missing = run.job("gone").read_job().unwrap_err().to_string();
        assert!(missing.contains("gone/job.json") && missing.contains("share"), "{missing}");
    }

    #[test]
    fn events_survive_a_line_cut_short() {
        let dir = tempfile::tempdir().unwrap();
        let job = JobDir { path: dir.path().into() };
        let event = Event {
            task: "7_0".into(),
            submission: "s".into(),
            kind: EventKind::Started,
            at: 1.0,
            host: "n1".into(),
            restarts: 0,
            detail: None,
        };
        job.append_event(&event).unwrap();
        OpenOptions::new().append(true).open(job.events_file()).unwrap().write_all(b"{\"task\": \"7_").unwrap();
        assert_eq!(job.events(), std::slice::from_ref(&event));
        let done = Event { kind: EventKind::Done, ..event.clone() };
        job.append_event(&done).unwrap();
        assert_eq!(job.events(), [event, done]);
        assert_eq!(file_name("rhine u1/β"), "rhine_u1__");
    }

    #[test]
    fn progress_reads_back_and_an_older_task_s_file_without_the_mass_still_reads() {
        let dir = tempfile::tempdir().unwrap();
        let job = JobDir { path: dir.path().into() };
        assert_eq!(job.progress(), None);
        let progress = TaskProgress {
            phase: "generation".into(),
            time: 1.5,
            grains: 900,
            contacts: 1200,
            mass_created: Some(0.4),
            shaking_until: None,
        };
        job.write_progress(&progress).unwrap();
        assert_eq!(job.progress(), Some(progress.clone()));
        fs::write(job.progress_file(), br#"{"phase": "shaking", "time": 2.0, "grains": 10, "contacts": 3}"#).unwrap();
        let older = TaskProgress {
            phase: "shaking".into(),
            time: 2.0,
            grains: 10,
            contacts: 3,
            mass_created: None,
            shaking_until: None,
        };
        assert_eq!(job.progress(), Some(older));
    }
}
