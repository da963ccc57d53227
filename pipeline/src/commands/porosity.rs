//! `sedpack porosity FILE.csv`: the §4.4 evaluation of any packing given as x,y,z,r rows in a
//! horizontally periodic square box.

use std::path::Path;

use analysis::csv::read_columns;
use anyhow::{Context, bail};
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
    read_columns(path, &["z", "r"])?
        .into_iter()
        .map(|(line, values)| match values[..] {
            [z, r] if r > 0.0 && r.is_finite() && z.is_finite() => Ok((z, r)),
            _ => bail!("{}, line {line}: r must be a positive number and z finite", path.display()),
        })
        .collect()
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
