//! Where a campaign's jobs run: on this machine's workers (`local`) or as Slurm job arrays
//! (`slurm`). The choice and its settings come from the command line, the campaign file's
//! `executor:` block and what the campaign was last submitted with, in that order of precedence,
//! and are stored with the campaign so that `resume` continues the same way.

use std::fmt;

use anyhow::{anyhow, bail};
use serde::{Deserialize, Serialize};

/// The executor of a campaign, as stored with it (local: nothing stored).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Executor {
    Local,
    Slurm(SlurmSettings),
}

/// How tasks are submitted to Slurm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SlurmSettings {
    /// More `sbatch` arguments, as one shell-quoted string; they override sedpack's own.
    pub sbatch: Option<String>,
    /// CPUs of each task, and threads of its packing.
    pub cpus_per_task: usize,
    /// Wall-time limit of each task.
    pub time: Option<TimeLimit>,
    /// Tasks of one array running at once (the `%N` throttle).
    pub max_parallel: Option<usize>,
}

impl SlurmSettings {
    /// The `sbatch` arguments split as a shell would.
    pub fn sbatch_args(&self) -> anyhow::Result<Vec<String>> {
        split_sbatch(self.sbatch.as_deref().unwrap_or(""))
    }
}

fn split_sbatch(text: &str) -> anyhow::Result<Vec<String>> {
    shlex::split(text).ok_or_else(|| anyhow!("unbalanced quotes in {text:?}"))
}

/// A wall-time limit, whole seconds; written as Slurm writes it, `[D-]HH:MM:SS`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TimeLimit(pub u64);

impl TimeLimit {
    pub fn parse(text: &str) -> anyhow::Result<TimeLimit> {
        let expected = || anyhow!("expected HH:MM:SS or D-HH:MM:SS, got {text:?}");
        let (days, clock) = match text.split_once('-') {
            Some((d, clock)) => (d.parse::<u64>().map_err(|_| expected())?, clock),
            None => (0, text),
        };
        let parts: Vec<u64> =
            clock.split(':').map(|p| p.parse::<u64>()).collect::<Result<_, _>>().map_err(|_| expected())?;
        let [h, m, s] = parts[..] else { return Err(expected()) };
        if m >= 60 || s >= 60 {
            return Err(expected());
        }
        let seconds = ((days * 24 + h) * 60 + m) * 60 + s;
        // Slurm counts time limits in whole minutes.
        if seconds < 60 {
            bail!("{text:?} is shorter than Slurm's smallest time limit, one minute");
        }
        Ok(TimeLimit(seconds))
    }

    /// How long before the limit a task is told to checkpoint and stop: a tenth of the limit,
    /// between 1 and 5 minutes, and at most half the limit (Slurm may signal up to a minute early).
    pub fn signal_lead(self) -> u64 {
        (self.0 / 10).clamp(60, 300).min(self.0 / 2)
    }
}

impl fmt::Display for TimeLimit {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let (days, rest) = (self.0 / 86_400, self.0 % 86_400);
        let clock = format!("{:02}:{:02}:{:02}", rest / 3600, rest % 3600 / 60, rest % 60);
        if days > 0 { write!(f, "{days}-{clock}") } else { f.write_str(&clock) }
    }
}

impl Serialize for TimeLimit {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for TimeLimit {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Clock;
        impl serde::de::Visitor<'_> for Clock {
            type Value = TimeLimit;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a time limit HH:MM:SS or D-HH:MM:SS")
            }
            fn visit_str<E: serde::de::Error>(self, text: &str) -> Result<TimeLimit, E> {
                TimeLimit::parse(text).map_err(E::custom)
            }
        }
        deserializer.deserialize_str(Clock)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    Local,
    Slurm,
}

/// Executor keys as given in a campaign file's `executor:` block or on the command line; None
/// where not given. The names are the command line's (`--cpus-per-task`) and the file's
/// (`cpus_per_task`).
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Request {
    pub kind: Option<Kind>,
    pub sbatch: Option<String>,
    pub cpus_per_task: Option<usize>,
    pub time: Option<TimeLimit>,
    pub max_parallel: Option<usize>,
}

impl Request {
    /// The request of a campaign file's `executor:` block; an error names the key (under
    /// `executor.`) and what it expects.
    pub fn checked_block(self) -> Result<Request, (&'static str, String)> {
        self.check("executor.")?;
        Ok(self)
    }

    /// This request where it says something, `base` elsewhere.
    pub fn over(self, base: Request) -> Request {
        Request {
            kind: self.kind.or(base.kind),
            sbatch: self.sbatch.or(base.sbatch),
            cpus_per_task: self.cpus_per_task.or(base.cpus_per_task),
            time: self.time.or(base.time),
            max_parallel: self.max_parallel.or(base.max_parallel),
        }
    }

    /// Keys that apply to Slurm only must not come with `local`, counts are at least 1 and
    /// `sbatch` splits; `prefix` turns a key into the caller's name for it.
    fn check(&self, prefix: &'static str) -> Result<(), (&'static str, String)> {
        let key = |file: &'static str, flag: &'static str| if prefix.is_empty() { flag } else { file };
        for (name, flag, value) in [
            ("executor.cpus_per_task", "--cpus-per-task", self.cpus_per_task),
            ("executor.max_parallel", "--max-parallel", self.max_parallel),
        ] {
            if value == Some(0) {
                return Err((key(name, flag), "expected at least 1, got 0".into()));
            }
        }
        if let Some(sbatch) = &self.sbatch {
            split_sbatch(sbatch).map_err(|e| (key("executor.sbatch", "--sbatch"), e.to_string()))?;
        }
        if self.kind == Some(Kind::Local) {
            let slurm_only = [
                ("executor.sbatch", "--sbatch", self.sbatch.is_some()),
                ("executor.cpus_per_task", "--cpus-per-task", self.cpus_per_task.is_some()),
                ("executor.time", "--time", self.time.is_some()),
                ("executor.max_parallel", "--max-parallel", self.max_parallel.is_some()),
            ];
            if let Some((name, flag, _)) = slurm_only.into_iter().find(|k| k.2) {
                return Err((key(name, flag), "applies to the slurm executor only".into()));
            }
        }
        Ok(())
    }

    /// What the command line asks; errors name the option.
    pub fn checked_flags(self) -> anyhow::Result<Request> {
        self.check("").map_err(|(flag, message)| anyhow!("{flag}: {message}"))?;
        Ok(self)
    }

    /// The executor this request gives on top of the one the campaign has (None: new or local).
    pub fn resolve(self, stored: Option<&Executor>) -> Executor {
        let base = match stored {
            Some(Executor::Slurm(s)) => Request {
                kind: Some(Kind::Slurm),
                sbatch: s.sbatch.clone(),
                cpus_per_task: Some(s.cpus_per_task),
                time: s.time,
                max_parallel: s.max_parallel,
            },
            Some(Executor::Local) | None => Request::default(),
        };
        // Slurm keys alone ask for Slurm: they mean nothing to the local workers.
        let slurm_keys =
            self.sbatch.is_some() || self.cpus_per_task.is_some() || self.time.is_some() || self.max_parallel.is_some();
        let kind = self.kind.or(slurm_keys.then_some(Kind::Slurm)).or(base.kind);
        let merged = self.over(base);
        match kind {
            None | Some(Kind::Local) => Executor::Local,
            Some(Kind::Slurm) => Executor::Slurm(SlurmSettings {
                sbatch: merged.sbatch,
                cpus_per_task: merged.cpus_per_task.unwrap_or(1),
                time: merged.time,
                max_parallel: merged.max_parallel,
            }),
        }
    }
}

impl Executor {
    /// The executor stored with a campaign: None is local.
    pub fn from_stored(value: Option<&serde_json::Value>) -> anyhow::Result<Executor> {
        match value {
            None => Ok(Executor::Local),
            Some(v) => serde_json::from_value(v.clone())
                .map_err(|e| anyhow!("the campaign's stored executor {v} is not readable: {e}")),
        }
    }

    /// What to store with the campaign: None for local.
    pub fn to_stored(&self) -> Option<serde_json::Value> {
        match self {
            Executor::Local => None,
            slurm => Some(serde_json::to_value(slurm).expect("settings are strings and numbers")),
        }
    }
}

impl fmt::Display for Executor {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            Executor::Local => f.write_str("local workers"),
            Executor::Slurm(s) => {
                write!(f, "slurm: --cpus-per-task {}", s.cpus_per_task)?;
                if let Some(time) = s.time {
                    write!(f, ", --time {time}")?;
                }
                if let Some(n) = s.max_parallel {
                    write!(f, ", --max-parallel {n}")?;
                }
                if let Some(args) = &s.sbatch {
                    write!(f, ", --sbatch {args:?}")?;
                }
                Ok(())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_limits_read_and_write_as_slurm_does() {
        assert_eq!(TimeLimit::parse("01:30:00").unwrap(), TimeLimit(5400));
        assert_eq!(TimeLimit::parse("2-00:00:30").unwrap().to_string(), "2-00:00:30");
        assert_eq!(TimeLimit(3600).to_string(), "01:00:00");
        for bad in ["90", "1:60:00", "x-01:00:00", "01:00", ""] {
            let error = TimeLimit::parse(bad).unwrap_err().to_string();
            assert!(error.contains("HH:MM:SS") && error.contains(&format!("{bad:?}")), "{error}");
        }
        assert!(TimeLimit::parse("00:00:30").unwrap_err().to_string().contains("one minute"));
        // A tenth, within [1, 5] minutes, at most half the limit.
        assert_eq!(TimeLimit(60).signal_lead(), 30);
        assert_eq!(TimeLimit(1200).signal_lead(), 120);
        assert_eq!(TimeLimit(86_400).signal_lead(), 300);
    }

    #[test]
    fn the_command_line_overrides_the_file_which_overrides_the_stored_executor() {
        let stored = Executor::Slurm(SlurmSettings {
            sbatch: Some("--partition=a".into()),
            cpus_per_task: 4,
            time: Some(TimeLimit(3600)),
            max_parallel: None,
        });
        let file = Request { cpus_per_task: Some(2), max_parallel: Some(8), ..Request::default() };
        let flags = Request { sbatch: Some("--partition=b".into()), ..Request::default() };
        let Executor::Slurm(s) = flags.over(file).resolve(Some(&stored)) else { panic!("slurm") };
        assert_eq!(
            (s.sbatch.as_deref(), s.cpus_per_task, s.time, s.max_parallel),
            (Some("--partition=b"), 2, Some(TimeLimit(3600)), Some(8))
        );
        // Nothing asked: the stored executor continues; a new campaign runs locally.
        assert_eq!(Request::default().resolve(Some(&stored)), stored);
        assert_eq!(Request::default().resolve(None), Executor::Local);
        let local = Request { kind: Some(Kind::Local), ..Request::default() };
        assert_eq!(local.resolve(Some(&stored)), Executor::Local);
        // Stored and read back.
        assert_eq!(Executor::from_stored(stored.to_stored().as_ref()).unwrap(), stored);
        assert_eq!(Executor::Local.to_stored(), None);
    }

    #[test]
    fn slurm_keys_with_the_local_executor_or_zero_counts_are_refused() {
        let local = Request { kind: Some(Kind::Local), time: Some(TimeLimit(60)), ..Request::default() };
        assert_eq!(local.checked_flags().unwrap_err().to_string(), "--time: applies to the slurm executor only");
        let block = Request { kind: Some(Kind::Local), max_parallel: Some(2), ..Request::default() };
        assert_eq!(block.checked_block().unwrap_err().0, "executor.max_parallel");
        let zero = Request { cpus_per_task: Some(0), ..Request::default() };
        assert_eq!(zero.checked_block().unwrap_err(), ("executor.cpus_per_task", "expected at least 1, got 0".into()));
        let quotes = Request { sbatch: Some("--comment='x".into()), ..Request::default() };
        assert!(quotes.checked_flags().unwrap_err().to_string().starts_with("--sbatch: unbalanced quotes"));
    }
}
