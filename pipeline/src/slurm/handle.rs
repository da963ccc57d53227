//! Who holds a running job of a Slurm campaign, written in the store's worker column: a
//! submission under way (claimed, not yet known to Slurm) or a Slurm array task.

use std::fmt;

/// The holder of a running job of a Slurm campaign.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Handle {
    /// Claimed by the `sedpack` process `pid` of `host` for its submission `token`, as the
    /// array's task `index`, before sbatch answered.
    Submitting { host: String, pid: u32, token: String, index: usize },
    /// The array task `ARRAY_INDEX`.
    Task { array: String, index: usize },
}

impl Handle {
    pub fn parse(worker: &str) -> Option<Handle> {
        if let Some(rest) = worker.strip_prefix("slurm-submitting:") {
            let mut f = rest.split(':');
            let (host, pid, token, index) = (f.next()?, f.next()?, f.next()?, f.next()?);
            return Some(Handle::Submitting {
                host: host.into(),
                pid: pid.parse().ok()?,
                token: token.into(),
                index: index.parse().ok()?,
            });
        }
        let (array, index) = worker.strip_prefix("slurm:")?.split_once('_')?;
        array.bytes().all(|b| b.is_ascii_digit()).then_some(())?;
        Some(Handle::Task { array: array.into(), index: index.parse().ok()? })
    }

    /// The Slurm task, `ARRAY_INDEX`, of a submitted job.
    pub fn task(&self) -> Option<String> {
        match self {
            Handle::Task { array, index } => Some(format!("{array}_{index}")),
            Handle::Submitting { .. } => None,
        }
    }
}

impl fmt::Display for Handle {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            Handle::Submitting { host, pid, token, index } => {
                write!(f, "slurm-submitting:{host}:{pid}:{token}:{index}")
            }
            Handle::Task { array, index } => write!(f, "slurm:{array}_{index}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn handles_read_back_and_other_workers_are_not_handles() {
        let submitting = Handle::Submitting { host: "login1".into(), pid: 42, token: "1a2b".into(), index: 3 };
        let task = Handle::Task { array: "1234".into(), index: 7 };
        for handle in [submitting, task.clone()] {
            assert_eq!(Handle::parse(&handle.to_string()), Some(handle));
        }
        assert_eq!(task.task().as_deref(), Some("1234_7"));
        for other in ["login1:42:0", "slurm:12_x", "slurm:a_1", "slurm-submitting:h:p:t:0"] {
            assert_eq!(Handle::parse(other), None, "{other}");
        }
    }
}
