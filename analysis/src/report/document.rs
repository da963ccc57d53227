//! The report as a list of blocks, rendered once to Markdown and once to self-contained HTML
//! so both files always say the same thing. Text uses two Markdown marks only, `code` and
//! **strong**, which the HTML renderer translates.

use std::fmt::Write as _;

pub enum Block {
    Heading(String),
    Subheading(String),
    Paragraph(String),
    List(Vec<String>),
    Table { header: Vec<String>, rows: Vec<Vec<String>> },
    Figure { file: String, caption: String, svg: String },
}

pub fn markdown(title: &str, blocks: &[Block]) -> String {
    let mut out = format!("# {title}\n\n");
    let mut figure = 0;
    for block in blocks {
        match block {
            Block::Heading(h) => {
                let _ = writeln!(out, "## {h}\n");
            }
            Block::Subheading(h) => {
                let _ = writeln!(out, "### {h}\n");
            }
            Block::Paragraph(p) => {
                let _ = writeln!(out, "{p}\n");
            }
            Block::List(items) => {
                for item in items {
                    let _ = writeln!(out, "- {item}");
                }
                out.push('\n');
            }
            Block::Table { header, rows } => {
                let line = |cells: &[String]| {
                    format!("| {} |\n", cells.iter().map(|c| c.replace('|', "\\|")).collect::<Vec<_>>().join(" | "))
                };
                out.push_str(&line(header));
                out.push_str(&format!("|{}\n", "---|".repeat(header.len())));
                for row in rows {
                    out.push_str(&line(row));
                }
                out.push('\n');
            }
            Block::Figure { file, caption, .. } => {
                figure += 1;
                let _ = writeln!(out, "![{caption}](figures/{file}.svg)\n\n*Figure {figure}: {caption}*\n");
            }
        }
    }
    out
}

/// Tables longer than this fold away in the HTML (`<details>`), so that the report reads
/// through; the Markdown shows them whole.
pub const FOLD_ROWS: usize = 15;

const STYLE: &str = "body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222;line-height:1.45}\
div.table{max-width:100%;overflow-x:auto}table{border-collapse:collapse;margin:1em 0;font-size:0.92em}\
th,td{border:1px solid #bbb;padding:0.25em 0.6em;text-align:left;vertical-align:top;overflow-wrap:anywhere}\
summary{cursor:pointer;color:#335}\
th{background:#eee;overflow-wrap:normal}td.num{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}\
td code,th code{white-space:nowrap}\
code{background:#f3f3f3;padding:0 0.2em}figure{margin:1.5em 0}svg{max-width:100%;height:auto}\
figcaption{font-style:italic;margin-top:0.3em}";

pub fn html(title: &str, blocks: &[Block]) -> String {
    let mut out = format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\"/>\n<title>{}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<h1>{}</h1>\n",
        escape(title),
        inline(title)
    );
    let mut figure = 0;
    for block in blocks {
        match block {
            Block::Heading(h) => {
                let _ = writeln!(out, "<h2>{}</h2>", inline(h));
            }
            Block::Subheading(h) => {
                let _ = writeln!(out, "<h3>{}</h3>", inline(h));
            }
            Block::Paragraph(p) => {
                let _ = writeln!(out, "<p>{}</p>", inline(p));
            }
            Block::List(items) => {
                out.push_str("<ul>\n");
                for item in items {
                    let _ = writeln!(out, "<li>{}</li>", inline(item));
                }
                out.push_str("</ul>\n");
            }
            Block::Table { header, rows } => {
                let fold = rows.len() > FOLD_ROWS;
                if fold {
                    let _ = writeln!(out, "<details>\n<summary>Show the {} rows of this table</summary>", rows.len());
                }
                out.push_str("<div class=\"table\">\n<table>\n<thead><tr>");
                for h in header {
                    let _ = write!(out, "<th>{}</th>", inline(h));
                }
                out.push_str("</tr></thead>\n<tbody>\n");
                for row in rows {
                    out.push_str("<tr>");
                    for cell in row {
                        let class = if is_numeric(cell) { " class=\"num\"" } else { "" };
                        let _ = write!(out, "<td{class}>{}</td>", inline(cell));
                    }
                    out.push_str("</tr>\n");
                }
                out.push_str("</tbody>\n</table>\n</div>\n");
                if fold {
                    out.push_str("</details>\n");
                }
            }
            Block::Figure { caption, svg, .. } => {
                figure += 1;
                let _ = writeln!(
                    out,
                    "<figure>\n{}\n<figcaption>Figure {figure}: {}</figcaption>\n</figure>",
                    svg.trim(),
                    inline(caption)
                );
            }
        }
    }
    out.push_str("</body>\n</html>\n");
    out
}

/// Escapes the five XML special characters, so the HTML is also well-formed XML.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// Escaped text with `code` and **strong** marks turned into elements.
fn inline(s: &str) -> String {
    marks(&escape(s))
}

/// [`inline`] on text already escaped; code may stand inside strong (**`name`**).
fn marks(escaped: &str) -> String {
    let mut out = String::new();
    let mut rest = escaped.to_string();
    while !rest.is_empty() {
        let code = rest.find('`');
        let strong = rest.find("**");
        let (at, mark, tag) = match (code, strong) {
            (Some(c), Some(b)) if b < c => (b, "**", "strong"),
            (Some(c), _) => (c, "`", "code"),
            (None, Some(b)) => (b, "**", "strong"),
            (None, None) => break,
        };
        let after = &rest[at + mark.len()..];
        let Some(end) = after.find(mark) else { break };
        let inner = if tag == "strong" { marks(&after[..end]) } else { after[..end].to_string() };
        let _ = write!(out, "{}<{tag}>{inner}</{tag}>", &rest[..at]);
        rest = after[end + mark.len()..].to_string();
    }
    out.push_str(&rest);
    out
}

fn is_numeric(cell: &str) -> bool {
    let bare = cell.trim_matches('*').replace('−', "-");
    let first = bare.split([' ', '±']).next().unwrap_or("");
    !first.is_empty() && first.parse::<f64>().is_ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inline_marks_become_elements_and_text_is_escaped() {
        assert_eq!(inline("a `x<y` and **b & c**"), "a <code>x&lt;y</code> and <strong>b &amp; c</strong>");
        assert_eq!(inline("unclosed `mark"), "unclosed `mark");
        assert_eq!(inline("is **`inv_EQ`** (x)"), "is <strong><code>inv_EQ</code></strong> (x)");
        assert!(is_numeric("**4.26**"));
        assert!(is_numeric("0.383 ± 0.002"));
        assert!(is_numeric("−0.011"));
        assert!(!is_numeric("inv_EQ"));
    }
}
