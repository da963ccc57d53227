//! CSV as sedpack writes and reads it: a field quoted only when it must be (RFC 4180), and the
//! numeric columns of a file found by their header names.

use std::path::{Path, PathBuf};

use thiserror::Error;

#[derive(Debug, Error)]
pub enum CsvError {
    #[error("{path}: cannot read: {source}")]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{path}, line {line}: {message}")]
    Line { path: PathBuf, line: usize, message: String },
}

/// A field as written: quoted when it holds a separator, a quote or a line break.
pub fn field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_string() }
}

/// The values of the named columns in every data row, with the row's line number. Names match
/// the header in any case, quoted or not, and other columns are ignored; blank lines and lines
/// starting with '#' are skipped. A missing column, a missing or non-numeric value and a file
/// without data rows are errors naming the file and the line.
pub fn read_columns(path: &Path, columns: &[&str]) -> Result<Vec<(usize, Vec<f64>)>, CsvError> {
    let text = std::fs::read_to_string(path).map_err(|source| CsvError::Read { path: path.into(), source })?;
    let error = |line: usize, message: String| CsvError::Line { path: path.into(), line, message };
    let mut lines =
        text.lines().enumerate().map(|(k, l)| (k + 1, l.trim())).filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let wanted = columns.join(",");
    let (header_line, header) =
        lines.next().ok_or_else(|| error(1, format!("empty file: expected a header with columns {wanted}")))?;
    let names: Vec<String> = header.split(',').map(|h| h.trim().trim_matches('"').to_ascii_lowercase()).collect();
    let at = columns
        .iter()
        .map(|want| {
            names
                .iter()
                .position(|n| *n == want.to_ascii_lowercase())
                .ok_or_else(|| error(header_line, format!("no column '{want}' in header '{header}'")))
        })
        .collect::<Result<Vec<usize>, _>>()?;
    let mut rows = Vec::new();
    for (line, row) in lines {
        let cells: Vec<&str> = row.split(',').map(str::trim).collect();
        let values = columns
            .iter()
            .zip(&at)
            .map(|(name, &k)| {
                let cell = cells.get(k).ok_or_else(|| error(line, format!("no value in column '{name}'")))?;
                cell.parse().map_err(|_| error(line, format!("column '{name}': '{cell}' is not a number")))
            })
            .collect::<Result<Vec<f64>, _>>()?;
        rows.push((line, values));
    }
    if rows.is_empty() {
        return Err(error(header_line, "no data below the header".into()));
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn awkward_fields_are_quoted() {
        assert_eq!(field("a,b"), "\"a,b\"");
        assert_eq!(field("say \"hi\""), "\"say \"\"hi\"\"\"");
        assert_eq!(field("plain"), "plain");
    }

    #[test]
    fn columns_are_found_by_name_and_bad_rows_named_by_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.csv");
        std::fs::write(&path, "# grains\n\"Id\",EL,fl\n1,0.8,0.5\n\n2,0.6,0.7\n").unwrap();
        assert_eq!(read_columns(&path, &["FL", "EL"]).unwrap(), [(3, vec![0.5, 0.8]), (5, vec![0.7, 0.6])]);
        std::fs::write(&path, "FL,EL\n0.5,0.8\n0.7\n").unwrap();
        let e = read_columns(&path, &["FL", "EL"]).unwrap_err().to_string();
        assert!(e.ends_with("t.csv, line 3: no value in column 'EL'"), "{e}");
        std::fs::write(&path, "FL\n").unwrap();
        let e = read_columns(&path, &["FL", "EL"]).unwrap_err().to_string();
        assert!(e.contains("line 1: no column 'EL'"), "{e}");
        std::fs::write(&path, "FL,EL\n").unwrap();
        assert!(read_columns(&path, &["FL"]).unwrap_err().to_string().contains("no data below the header"));
    }
}
