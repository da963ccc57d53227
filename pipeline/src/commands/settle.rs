//! `sedpack settle`: one grain dropped in still water with the second paper's fluid forces,
//! its terminal velocity, drag coefficient, Reynolds number, time to 99 % and orientation,
//! beside Haider & Levenspiel's (1989) and Dietrich's (1982) correlations for a grain of the
//! same volume and form.

use std::sync::Arc;

use anyhow::{Context, bail};
use nalgebra::Vector3;
use serde::Serialize;
use solver::dem::shape::{ConvexPolyhedron, Polyhedron};
use solver::dem::{Material, Shape};
use solver::fluid::drag::FluidProperties;
use solver::fluid::settling::{Drop, Scales, dietrich_velocity, drop, haider_levenspiel_velocity, release_orientation};
use solver::fluid::sphericity::sphericity;
use solver::grain::simplify::DEFAULT_MAX_FACES;
use solver::grain::{FormParameters, bonded_grain};
use solver::packing::in_range;

use crate::cli::{SettleArgs, SettleShape};
use crate::meshes;
use crate::outln;
use crate::output::{Table, number, print_json};

#[derive(Debug, Serialize)]
struct Correlation {
    terminal_velocity: f64,
    drag_coefficient: f64,
}

#[derive(Debug, Serialize)]
struct Orientation {
    short_axis_tilt: Option<f64>,
    long_axis_dip: Option<f64>,
}

#[derive(Debug, Serialize)]
struct Report {
    shape: &'static str,
    /// The bonded grain's Zingg class.
    #[serde(skip_serializing_if = "Option::is_none")]
    class: Option<&'static str>,
    #[serde(rename = "L")]
    l: f64,
    #[serde(rename = "I")]
    i: f64,
    #[serde(rename = "S")]
    s: f64,
    #[serde(rename = "D_n")]
    nominal_diameter: f64,
    density: f64,
    fluid_density: f64,
    viscosity: f64,
    terminal_velocity: f64,
    drag_coefficient: f64,
    #[serde(rename = "Re_p")]
    reynolds: f64,
    time_to_99: f64,
    drift: f64,
    orientation: Option<Orientation>,
    sphericity: f64,
    #[serde(rename = "CSF")]
    corey: f64,
    roundness: f64,
    haider_levenspiel: Correlation,
    dietrich: Correlation,
    notes: Vec<String>,
}

pub fn run(args: &SettleArgs) -> anyhow::Result<()> {
    let checked = |key, value, ok, expected| in_range(key, value, ok, expected).map_err(anyhow::Error::from);
    checked("--density", args.density, args.density > 0.0, "a density > 0 (kg/m³)")?;
    checked(
        "--fluid-density",
        args.fluid_density,
        args.fluid_density >= 0.0 && args.fluid_density < args.density,
        "≥ 0 and below --density (the grain must sink)",
    )?;
    checked("--viscosity", args.viscosity, args.viscosity > 0.0, "a viscosity > 0 (Pa·s)")?;
    let (form, kind) = match (&args.lis, args.d, args.shape) {
        (Some(lis), _, shape) => {
            let form = FormParameters::new(lis[0], lis[1], lis[2]).context("--lis")?;
            let kind = match shape.unwrap_or(SettleShape::Ellipsoid) {
                SettleShape::Sphere => bail!("--shape sphere drops a sphere of diameter --d, not --lis"),
                other => other,
            };
            (form, kind)
        }
        (None, Some(d), None | Some(SettleShape::Sphere)) => {
            checked("--d", d, d > 0.0, "a diameter > 0 (m)")?;
            (FormParameters { l: d, i: d, s: d }, SettleShape::Sphere)
        }
        (None, Some(_), Some(_)) => bail!("--d drops a sphere: give --lis L I S for other shapes"),
        (None, None, _) => unreachable!("clap requires --lis or --d"),
    };
    let (shape, name, class): (Shape, &str, Option<&str>) = match kind {
        SettleShape::Sphere => (Shape::Sphere { radius: form.l / 2.0 }, "sphere", None),
        SettleShape::Ellipsoid => {
            (Shape::Ellipsoid { semi_axes: Vector3::new(form.l, form.i, form.s) / 2.0 }, "ellipsoid", None)
        }
        SettleShape::BondedSpheres => {
            let grain = bonded_grain(&form).context("--lis")?;
            (Shape::from(&grain), "bonded-spheres", Some(grain.class.name()))
        }
        SettleShape::Mesh => {
            let library = meshes::load(meshes::RHINE, DEFAULT_MAX_FACES, std::path::Path::new("."))?;
            let unit = library.meshes.first().context("the Rhine library holds two scans")?;
            let base = Arc::new(ConvexPolyhedron::new(unit.mesh())?);
            (Shape::Polyhedron(Box::new(Polyhedron::with_form(base, &form)?)), "mesh", None)
        }
    };
    let material = Material { density: args.density, fluid_density: args.fluid_density, ..Material::default() };
    let fluid = FluidProperties { density: args.fluid_density, viscosity: args.viscosity };
    let settling =
        drop(&Drop { shape: shape.clone(), material, viscosity: args.viscosity, orientation: release_orientation() })?;

    // The correlations for a grain of the simulated body's volume and of the form it stands for:
    // a mesh is its own form; a bonded grain stands for the ellipsoid with its axes.
    let phi = match kind {
        SettleShape::Mesh => sphericity(&shape),
        _ => sphericity(&Shape::Ellipsoid { semi_axes: Vector3::new(form.l, form.i, form.s) / 2.0 }),
    };
    let corey = form.s / (form.l * form.i).sqrt();
    let roundness = args.roundness.unwrap_or(if kind == SettleShape::Mesh { 3.5 } else { 6.0 });
    let g = -material.gravity.z;
    let scales = Scales::new(&fluid, args.density, g);
    let d = settling.nominal_diameter;
    let correlation = |velocity: f64| Correlation {
        terminal_velocity: velocity,
        drag_coefficient: scales.drag_coefficient(d, velocity),
    };
    let mut notes = Vec::new();
    if phi < 0.5 {
        notes.push(format!("sphericity {phi:.3} is below 0.5, where Haider & Levenspiel fitted their Eq. 20"));
    }
    let dstar = (d / scales.length).powi(3);
    if corey < 0.2 || dstar > 5e9 {
        notes.push(format!(
            "Dietrich's fit covers CSF ≥ 0.2 and D* ≤ 5 × 10⁹ (here CSF {corey:.3}, D* {})",
            number(dstar)
        ));
    }
    let report = Report {
        shape: name,
        class,
        l: form.l,
        i: form.i,
        s: form.s,
        nominal_diameter: d,
        density: args.density,
        fluid_density: args.fluid_density,
        viscosity: args.viscosity,
        terminal_velocity: settling.terminal_velocity,
        drag_coefficient: settling.drag_coefficient,
        reynolds: settling.reynolds,
        time_to_99: settling.time_to_99,
        drift: settling.drift,
        orientation: settling
            .orientation
            .map(|o| Orientation { short_axis_tilt: o.short_axis_tilt, long_axis_dip: o.long_axis_dip }),
        sphericity: phi,
        corey,
        roundness,
        haider_levenspiel: correlation(haider_levenspiel_velocity(&scales, d, phi)),
        dietrich: correlation(dietrich_velocity(&scales, d, corey, roundness)),
        notes,
    };
    if args.json {
        return print_json(&report);
    }
    outln!("{name} settling in still water (Sun & Xiao's drag and lift)")?;
    let mut table = Table::default();
    if let Some(class) = report.class {
        table.row("Zingg class", class);
    }
    let angle = |a: Option<f64>| a.map_or_else(|| "not defined (symmetric)".to_string(), |a| format!("{a:.1}°"));
    table
        .row("L, I, S", format!("{} m, {} m, {} m", number(form.l), number(form.i), number(form.s)))
        .row("nominal diameter D_n", format!("{} m", number(d)))
        .row("terminal velocity", format!("{} m/s", number(report.terminal_velocity)))
        .row("drag coefficient C_D", number(report.drag_coefficient))
        .row("Re_p", number(report.reynolds))
        .row("time to 99 %", format!("{} s", number(report.time_to_99)));
    if let Some(o) = &report.orientation {
        table
            .row("short axis from vertical", angle(o.short_axis_tilt))
            .row("long axis from horizontal", angle(o.long_axis_dip));
    }
    table
        .row("sphericity φ, CSF, Powers P", format!("{:.3}, {:.3}, {}", phi, corey, roundness))
        .row("Haider & Levenspiel (1989)", correlation_text(&report.haider_levenspiel))
        .row("Dietrich (1982)", correlation_text(&report.dietrich));
    for note in &report.notes {
        table.row("note", note.clone());
    }
    table.print()?;
    Ok(())
}

fn correlation_text(c: &Correlation) -> String {
    format!("{} m/s, C_D {}", number(c.terminal_velocity), number(c.drag_coefficient))
}
