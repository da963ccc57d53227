//! Printing results: one JSON object with `--json`, an aligned table otherwise. Every write to
//! standard output returns its error instead of panicking, so that a closed pipe
//! (`sedpack … | head`) ends the command, and `main` ends it quietly.

use serde::Serialize;

/// `println!` that returns the write's error rather than panicking on it.
#[macro_export]
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($arg)*)
    }};
}

pub fn print_json(value: &impl Serialize) -> anyhow::Result<()> {
    outln!("{}", serde_json::to_string_pretty(value)?)?;
    Ok(())
}

/// Whether an error is standard output closed under us (`EPIPE`): the reader has all it wanted.
pub fn is_closed_pipe(error: &anyhow::Error) -> bool {
    error
        .chain()
        .any(|cause| cause.downcast_ref::<std::io::Error>().is_some_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe))
}

/// A two-column table of labelled values, printed with aligned columns.
#[derive(Default)]
pub struct Table {
    rows: Vec<(String, String)>,
}

impl Table {
    pub fn row(&mut self, label: impl Into<String>, value: impl Into<String>) -> &mut Self {
        self.rows.push((label.into(), value.into()));
        self
    }

    pub fn print(&self) -> std::io::Result<()> {
        let width = self.rows.iter().map(|(l, _)| l.chars().count()).max().unwrap_or(0);
        for (label, value) in &self.rows {
            outln!("{label:<width$}  {value}")?;
        }
        Ok(())
    }
}

/// A number with 6 significant digits, as a person reads it.
pub fn number(x: f64) -> String {
    if x == 0.0 || (1e-3..1e6).contains(&x.abs()) {
        // Zero apart: its log10 is −∞, which `as i32` makes i32::MIN, and 5 minus that overflows.
        let digits = if x == 0.0 { 0 } else { (5 - x.abs().log10().floor() as i32).max(0) as usize };
        format!("{x:.digits$}")
    } else {
        format!("{x:.5e}")
    }
}

/// A packing's phase in words, with the simulated time its shaking ends while it shakes
/// ("shaking until 6.25 s"): the one phase whose end is known in advance.
pub fn phase_words(phase: &str, shaking_until: Option<f64>) -> String {
    match shaking_until {
        Some(until) => format!("{phase} until {until:.2} s"),
        None => phase.to_string(),
    }
}
