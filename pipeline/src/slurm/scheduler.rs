//! Slurm's own commands, run as a user would run them: `sbatch`, `squeue`, `sacct`, `scancel`
//! and `scontrol`. Every failure names the command and gives Slurm's words.

use std::collections::{BTreeSet, HashMap};
use std::process::Command;

use anyhow::{Context, anyhow, bail};

/// What Slurm says of one array task (`ARRAY_INDEX`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TaskState {
    pub task: String,
    /// Slurm's state name: PENDING, RUNNING, COMPLETED, CANCELLED, …
    pub state: String,
    /// Why it waits or ended, where Slurm says (`JobArrayTaskLimit`, `TimeLimit`, …).
    pub reason: Option<String>,
    /// `EXIT:SIGNAL`, where known (sacct only).
    pub exit_code: Option<String>,
}

impl TaskState {
    /// Whether the task may still run or write: anything but a final state.
    pub fn is_active(&self) -> bool {
        !FINAL.contains(&self.state.as_str())
    }
}

/// Slurm's states after which a job runs no more (unless requeued, which shows as PENDING).
const FINAL: &[&str] = &[
    "COMPLETED",
    "FAILED",
    "CANCELLED",
    "TIMEOUT",
    "NODE_FAIL",
    "OUT_OF_MEMORY",
    "BOOT_FAIL",
    "DEADLINE",
    "PREEMPTED",
];

/// Runs a Slurm command and gives its standard output.
fn run(program: &str, args: &[String]) -> anyhow::Result<String> {
    let output = Command::new(program).args(args).output().map_err(|e| {
        if e.kind() == std::io::ErrorKind::NotFound {
            anyhow!(
                "{program} is not on PATH: the slurm executor runs Slurm's commands (sbatch, squeue, \
                 scancel, scontrol, and sacct where accounting exists) on the host that submits the campaign"
            )
        } else {
            anyhow!("{program}: {e}")
        }
    })?;
    if !output.status.success() {
        let said = String::from_utf8_lossy(&output.stderr);
        let said: Vec<&str> = said.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
        let hint = if said.iter().any(|l| l.contains("Unable to contact slurm controller")) {
            " (is slurmctld running, and reachable from this host?)"
        } else {
            ""
        };
        bail!("`{program} {}` failed ({}): {}{hint}", args.join(" "), output.status, said.join("; "));
    }
    Ok(String::from_utf8_lossy(&output.stdout).into_owned())
}

fn strings(args: &[&str]) -> Vec<String> {
    args.iter().map(|a| a.to_string()).collect()
}

/// The cluster's MaxArraySize: an array holds task indices 0 … MaxArraySize − 1.
pub fn max_array_size() -> anyhow::Result<usize> {
    let config = run("scontrol", &strings(&["show", "config"]))?;
    config
        .lines()
        .find_map(|l| l.strip_prefix("MaxArraySize")?.trim_start().strip_prefix('=')?.trim().parse().ok())
        .context("`scontrol show config` gives no MaxArraySize")
}

/// Submits a batch script with these arguments; gives the array's job id.
pub fn sbatch(args: &[String]) -> anyhow::Result<String> {
    let mut all = strings(&["--parsable"]);
    all.extend_from_slice(args);
    let out = run("sbatch", &all)?;
    // --parsable prints "ID" or "ID;CLUSTER".
    let id = out.trim().split(';').next().unwrap_or("");
    if id.is_empty() || !id.bytes().all(|b| b.is_ascii_digit()) {
        bail!("sbatch answered {out:?}, not a job id");
    }
    Ok(id.to_string())
}

/// What the controller knows of these arrays' tasks: the ones queued or running, and the ones
/// that ended within MinJobAge.
fn squeue(arrays: &[String]) -> anyhow::Result<Vec<TaskState>> {
    if arrays.is_empty() {
        return Ok(Vec::new());
    }
    let args = vec![
        "--noheader".into(),
        "--array".into(),
        "--states=all".into(),
        format!("--jobs={}", arrays.join(",")),
        "--format=%i|%T|%r".into(),
    ];
    let out = match run("squeue", &args) {
        Ok(out) => out,
        // The controller has forgotten every one of them.
        Err(e) if e.to_string().contains("Invalid job id specified") => return Ok(Vec::new()),
        Err(e) => return Err(e),
    };
    Ok(out
        .lines()
        .filter_map(|l| {
            let mut f = l.split('|');
            let (task, state, reason) = (f.next()?, f.next()?, f.next()?);
            Some(TaskState {
                task: task.to_string(),
                state: state.to_string(),
                reason: Some(reason.to_string()).filter(|r| r != "None"),
                exit_code: None,
            })
        })
        .collect())
}

/// Slurm's word on these tasks (`ARRAY_INDEX`): the controller's, and the accounting's for
/// tasks the controller has forgotten, where accounting exists. A task neither knows is absent.
pub fn states(tasks: &[String]) -> anyhow::Result<HashMap<String, TaskState>> {
    let arrays: Vec<String> = tasks
        .iter()
        .filter_map(|t| Some(t.split_once('_')?.0.to_string()))
        .collect::<BTreeSet<_>>()
        .into_iter()
        .collect();
    let mut known: HashMap<String, TaskState> = squeue(&arrays)?.into_iter().map(|t| (t.task.clone(), t)).collect();
    if tasks.iter().any(|t| !known.contains_key(t))
        && let Some(accounted) = sacct(&arrays)?
    {
        // An array cancelled before any task started has one record, under the array's id.
        let mut whole: HashMap<String, TaskState> = HashMap::new();
        for t in accounted {
            match t.task.split_once('_') {
                Some((_, index)) if !index.starts_with('[') => {
                    known.entry(t.task.clone()).or_insert(t);
                }
                _ => {
                    let array = t.task.split('_').next().unwrap_or_default().to_string();
                    whole.insert(array, t);
                }
            }
        }
        for task in tasks {
            if let (false, Some(array)) = (known.contains_key(task), task.split_once('_').map(|(a, _)| a))
                && let Some(t) = whole.get(array)
            {
                known.insert(task.clone(), TaskState { task: task.clone(), ..t.clone() });
            }
        }
    }
    Ok(known)
}

/// The array submitted with job name `name` and comment `comment`, if the controller knows it.
pub fn find_submission(name: &str, comment: &str) -> anyhow::Result<Option<String>> {
    let args = strings(&["--noheader", "--states=all", &format!("--name={name}"), "--format=%F|%k"]);
    let out = run("squeue", &args)?;
    Ok(out.lines().find_map(|l| {
        let (array, k) = l.split_once('|')?;
        (k == comment).then(|| array.to_string())
    }))
}

/// The accounting's final word on these arrays' tasks (the last run of each); None when the
/// cluster keeps no accounting.
fn sacct(arrays: &[String]) -> anyhow::Result<Option<Vec<TaskState>>> {
    if arrays.is_empty() {
        return Ok(Some(Vec::new()));
    }
    let args = vec![
        "--noheader".into(),
        "--parsable2".into(),
        "--allocations".into(),
        format!("--jobs={}", arrays.join(",")),
        "--format=JobID,State,ExitCode,Reason".into(),
    ];
    let out = match run("sacct", &args) {
        Ok(out) => out,
        Err(e) if e.to_string().contains("accounting storage is disabled") => return Ok(None),
        Err(e) => return Err(e),
    };
    Ok(Some(
        out.lines()
            .filter_map(|l| {
                let mut f = l.split('|');
                let (task, state, exit, reason) = (f.next()?, f.next()?, f.next()?, f.next()?);
                // "CANCELLED by 0": the state, without who.
                let state = state.split_whitespace().next()?.to_string();
                Some(TaskState {
                    task: task.to_string(),
                    state,
                    reason: Some(reason.to_string()).filter(|r| r != "None" && !r.is_empty()),
                    exit_code: Some(exit.to_string()),
                })
            })
            .collect(),
    ))
}

/// Cancels these arrays' or tasks' jobs.
pub fn scancel(ids: &[String]) -> anyhow::Result<()> {
    if !ids.is_empty() {
        run("scancel", ids)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn final_states_are_told_from_active_ones() {
        let state = |s: &str| TaskState { task: "1_0".into(), state: s.into(), reason: None, exit_code: None };
        for active in ["PENDING", "RUNNING", "COMPLETING", "REQUEUED", "REQUEUE_HOLD", "CONFIGURING", "SUSPENDED"] {
            assert!(state(active).is_active(), "{active}");
        }
        for ended in ["COMPLETED", "FAILED", "CANCELLED", "TIMEOUT", "NODE_FAIL", "OUT_OF_MEMORY"] {
            assert!(!state(ended).is_active(), "{ended}");
        }
    }

    #[test]
    fn a_missing_command_says_what_the_executor_needs() {
        let error = run("sedpack-no-such-sbatch", &[]).unwrap_err().to_string();
        assert!(error.contains("sedpack-no-such-sbatch is not on PATH") && error.contains("sbatch, squeue"), "{error}");
        let error = run("false", &strings(&["x"])).unwrap_err().to_string();
        assert!(error.starts_with("`false x` failed (exit status: 1)"), "{error}");
    }
}
