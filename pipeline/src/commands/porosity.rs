//! `sedpack porosity FILE.csv`: the §4.4 evaluation of any packing given as x,y,z,r rows in a
//! horizontally periodic square box.

use std::path::Path;

use anyhow::{Context, anyhow, bail};
use serde::Serialize;
use solver::porosity::{PorositySettings, ProfilePoint, evaluate};

use crate::cli::PorosityArgs;
use crate::output::{Table, number, print_json};

#[derive(Serialize)]
struct Evaluation {
    bulk_porosity: f64,
    z_minus: f64,
    z_plus: f64,
    surface: f64,
    particles: usize,
    profile: Vec<ProfilePoint>,
}

/// (z, r) of every row; the header must name columns z and r (x and y may be present).
fn read_spheres(path: &Path) -> anyhow::Result<Vec<(f64, f64)>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
    let (_, header) = lines.next().ok_or_else(|| anyhow!("{}: empty file", path.display()))?;
    let columns: Vec<&str> = header.split(',').map(str::trim).collect();
    let find = |name: &str| {
        columns
            .iter()
            .position(|c| *c == name)
            .ok_or_else(|| anyhow!("{}: line 1: no column '{name}' (expected a header x,y,z,r)", path.display()))
    };
    let (iz, ir) = (find("z")?, find("r")?);
    let mut spheres = Vec::new();
    for (n, line) in lines {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let value = |i: usize, name: &str| -> anyhow::Result<f64> {
            let raw =
                fields.get(i).ok_or_else(|| anyhow!("{}: line {}: missing column '{name}'", path.display(), n + 1))?;
            raw.parse().map_err(|_| anyhow!("{}: line {}: {name} = '{raw}' is not a number", path.display(), n + 1))
        };
        let (z, r) = (value(iz, "z")?, value(ir, "r")?);
        if !(r > 0.0 && r.is_finite() && z.is_finite()) {
            bail!("{}: line {}: r must be a positive number and z finite", path.display(), n + 1);
        }
        spheres.push((z, r));
    }
    Ok(spheres)
}

pub fn run(args: &PorosityArgs) -> anyhow::Result<()> {
    for (name, value) in [("--width", args.width), ("--slice", args.slice)] {
        if !(value > 0.0 && value.is_finite()) {
            bail!("{name} = {value} is out of range: expected a length > 0 (m)");
        }
    }
    if !(args.trim >= 0.0 && args.trim.is_finite()) {
        bail!("--trim = {} is out of range: expected a length ≥ 0 (m)", args.trim);
    }
    if !(args.cutoff > 0.0 && args.cutoff < 1.0) {
        bail!("--cutoff = {} is out of range: expected a porosity in (0, 1)", args.cutoff);
    }
    let spheres = read_spheres(&args.file)?;
    let settings = PorositySettings { slice: args.slice, cutoff: args.cutoff, trim: args.trim };
    let p =
        evaluate(&spheres, args.width * args.width, &settings).with_context(|| format!("{}", args.file.display()))?;
    let evaluation = Evaluation {
        bulk_porosity: p.bulk,
        z_minus: p.z_minus,
        z_plus: p.z_plus,
        surface: p.surface,
        particles: spheres.len(),
        profile: p.profile,
    };
    if args.json {
        return print_json(&evaluation);
    }
    let mut table = Table::default();
    table
        .row("bulk porosity", format!("{:.4}", evaluation.bulk_porosity))
        .row("evaluated", format!("{} m – {} m", number(evaluation.z_minus), number(evaluation.z_plus)))
        .row("surface", format!("{} m", number(evaluation.surface)))
        .row("particles", evaluation.particles.to_string());
    table.print()?;
    Ok(())
}
