//! `sedpack forms`: the form of one grain (--lis, --mesh) or of a form distribution.

use anyhow::{Context, bail};
use serde_json::{Map, Value, json};
use solver::grain::simplify::{DEFAULT_MAX_FACES, simplify};
use solver::grain::{
    Angularity, EquivalentEllipsoid, FormDistribution, FormParameters, RHINE_FORMS, TriMesh, bonded_grain,
    ellipsoid_mass,
};

use crate::cli::{DistributionArgs, FormsArgs};
use crate::meshes;
use crate::outln;
use crate::output::{Table, number, print_json};

pub fn run(args: &FormsArgs) -> anyhow::Result<()> {
    if args.faces.is_some() && args.mesh.is_none() && args.library.is_none() {
        bail!("--faces: simplifies a --mesh or a --library; there is none to simplify");
    }
    if let Some(source) = &args.library {
        return library(source, args.faces.unwrap_or(DEFAULT_MAX_FACES), args.json);
    }
    let (record, title) = if let Some(lis) = &args.lis {
        let form = FormParameters::new(lis[0], lis[1], lis[2]).context("--lis")?;
        (grain_record(&form, form.ellipsoid_volume()), "grain (ellipsoid with full axes L, I, S)".to_string())
    } else if let Some(path) = &args.mesh {
        let mut mesh = TriMesh::from_file(path)?;
        let mut volume_change = None;
        if let Some(faces) = args.faces {
            let simplified = simplify(&mesh, faces).with_context(|| format!("{}: --faces {faces}", path.display()))?;
            volume_change = Some(simplified.volume_change);
            mesh = simplified.mesh;
        }
        let props = mesh.mass_properties();
        let form = EquivalentEllipsoid::of(&props).form().with_context(|| format!("{}", path.display()))?;
        let mut record = grain_record(&form, props.volume);
        record.insert("triangles".into(), json!(mesh.triangles().len()));
        if let Some(change) = volume_change {
            record.insert("volume_change".into(), json!(change));
        }
        record.insert(
            "center_of_mass".into(),
            json!([props.center_of_mass.x, props.center_of_mass.y, props.center_of_mass.z]),
        );
        (record, format!("mesh {}", path.display()))
    } else if let Some(lis) = &args.bonded {
        let form = FormParameters::new(lis[0], lis[1], lis[2]).context("--bonded")?;
        (bonded_record(&form)?, "bonded-sphere grain (Sun & Xiao, §2.4 and Appendix)".to_string())
    } else {
        let d = args.distribution.given().expect("clap requires --lis, --mesh, --bonded or the distribution");
        (distribution_record(&d)?, "form distribution (§7.1, §7.3)".to_string())
    };
    if args.json {
        return print_json(&record);
    }
    outln!("{title}")?;
    let mut table = Table::default();
    for (key, value) in &record {
        match value {
            Value::Number(n) if n.is_u64() => table.row(key, n.to_string()),
            Value::Number(n) => table.row(key, number(n.as_f64().unwrap_or(f64::NAN))),
            Value::Null => table.row(key, "undefined"),
            Value::String(text) => table.row(key, text.clone()),
            Value::Array(items) if key == "notes" => {
                items.iter().for_each(|n| {
                    table.row("note", n.as_str().unwrap_or_default());
                });
                &mut table
            }
            Value::Object(inner) => {
                for (k, v) in inner {
                    table.row(format!("{key}.{k}"), v.as_f64().map_or_else(|| v.to_string(), number));
                }
                &mut table
            }
            Value::Array(items) if key == "spheres" => {
                items.iter().for_each(|sphere| {
                    table.row(
                        "sphere",
                        format!(
                            "centre {} radius {}",
                            sphere["center"],
                            number(sphere["radius"].as_f64().unwrap_or(f64::NAN))
                        ),
                    );
                });
                &mut table
            }
            other => table.row(key, other.to_string()),
        };
    }
    table.print()?;
    Ok(())
}

/// L, I, S, D, volume, the 13 factors and their inverses (null where undefined, with a note).
pub fn grain_record(form: &FormParameters, volume: f64) -> Map<String, Value> {
    let mut record = Map::new();
    for (key, value) in [("L", form.l), ("I", form.i), ("S", form.s), ("D", form.size()), ("volume", volume)] {
        record.insert(key.into(), json!(value));
    }
    let mut notes = Vec::new();
    let factors = form.factors();
    for (prefix, inverse) in [("", false), ("inv_", true)] {
        for (factor, value, inverse_value) in factors.iter() {
            let key = format!("{prefix}{}", factor.symbol());
            match if inverse { inverse_value } else { value } {
                Ok(v) => record.insert(key, json!(v)),
                Err(why) => {
                    notes.push(format!("{key} is {}", why.explain()));
                    record.insert(key, Value::Null)
                }
            };
        }
    }
    record.insert("notes".into(), json!(notes));
    record
}

/// The class, component spheres (grain frame, centre of mass at the origin), volume and
/// principal moments (per unit density, ascending), beside the ellipsoid with full axes L, I, S.
fn bonded_record(form: &FormParameters) -> anyhow::Result<Map<String, Value>> {
    let grain = bonded_grain(form)?;
    let ellipsoid = ellipsoid_mass(form);
    let mut record = Map::new();
    record.insert("L".into(), json!(form.l));
    record.insert("I".into(), json!(form.i));
    record.insert("S".into(), json!(form.s));
    record.insert("class".into(), json!(grain.class.name()));
    let spheres: Vec<Value> = grain
        .spheres
        .iter()
        .map(|c| json!({"center": [c.center.x, c.center.y, c.center.z], "radius": c.radius}))
        .collect();
    record.insert("spheres".into(), json!(spheres));
    record.insert("volume".into(), json!(grain.volume));
    record.insert("inertia".into(), json!([grain.inertia.x, grain.inertia.y, grain.inertia.z]));
    record.insert(
        "ellipsoid".into(),
        json!({"volume": ellipsoid.volume, "inertia": [ellipsoid.inertia.x, ellipsoid.inertia.y, ellipsoid.inertia.z]}),
    );
    Ok(record)
}

fn distribution_record(d: &DistributionArgs) -> anyhow::Result<Map<String, Value>> {
    let dist = FormDistribution::new(d.mu_fl, d.sigma_fl, d.mu_el, d.sigma_el)?;
    let (mu_eq, sigma_eq) = dist.equancy_statistics();
    let mut record = Map::new();
    for (key, value) in [
        ("mu_FL", d.mu_fl),
        ("sigma_FL", d.sigma_fl),
        ("mu_EL", d.mu_el),
        ("sigma_EL", d.sigma_el),
        ("mu_EQ", mu_eq),
        ("sigma_EQ", sigma_eq),
    ] {
        record.insert(key.into(), json!(value));
    }
    // What the grains will actually have after redrawing outside [0.1, 1].
    record.insert("truncated".into(), serde_json::to_value(dist.truncated_moments())?);
    Ok(record)
}

/// A column of `forms --library`: JSON key, table heading, value of a mesh.
type Column = (&'static str, &'static str, fn(&Angularity) -> f64);

const LIBRARY_COLUMNS: [Column; 8] = [
    ("FL", "FL", |a| a.form.s / a.form.i),
    ("EL", "EL", |a| a.form.i / a.form.l),
    ("sphericity", "sphericity", |a| a.sphericity),
    ("ellipsoid_sphericity", "ellipsoid", |a| a.ellipsoid_sphericity),
    ("relative_sphericity", "relative", Angularity::relative_sphericity),
    ("volume_ratio", "volume", |a| a.volume_ratio),
    ("largest_facet", "facet", |a| a.largest_facet),
    ("farthest_vertex", "farthest", |a| a.farthest_vertex),
];

/// One row per mesh of a library (own form, sphericities, angularity) and their means and
/// standard deviations beside the Rhine form distribution of Table 2, which the paper's 63 scans
/// follow: what a packing poured from the library's own forms draws from.
fn library(source: &str, faces: usize, json: bool) -> anyhow::Result<()> {
    let source = meshes::resolve(source, &std::env::current_dir()?).with_context(|| {
        format!("--library {source}: expected builtin:rhine, builtin:pebbles or a folder of meshes")
    })?;
    let mut rows = Vec::new();
    for (path, unit) in meshes::prepare(&source, faces).with_context(|| format!("--library {source}"))? {
        // A folder's meshes are named by their file names: the folder heads the table.
        let name = std::path::Path::new(&path).file_name().map_or(path.clone(), |n| n.to_string_lossy().into_owned());
        let mesh = unit.rescaled(&unit.original_form());
        let angularity = Angularity::of(&mesh).with_context(|| format!("{source}: {name}"))?;
        rows.push((name, mesh.triangles().len(), angularity));
    }
    let summary: Vec<(f64, f64)> = LIBRARY_COLUMNS
        .iter()
        .map(|(_, _, value)| mean_std(&rows.iter().map(|(_, _, a)| value(a)).collect::<Vec<_>>()))
        .collect();
    let table2 = RHINE_FORMS;
    if json {
        let meshes: Vec<Value> = rows
            .iter()
            .map(|(name, triangles, a)| {
                let mut row = Map::new();
                row.insert("mesh".into(), json!(name));
                row.insert("triangles".into(), json!(triangles));
                for (key, _, value) in &LIBRARY_COLUMNS {
                    row.insert((*key).into(), json!(value(a)));
                }
                Value::Object(row)
            })
            .collect();
        let summary: Map<String, Value> = LIBRARY_COLUMNS
            .iter()
            .zip(&summary)
            .map(|((key, _, _), (mean, std))| ((*key).into(), json!({"mean": mean, "std": std})))
            .collect();
        return print_json(&json!({
            "library": source,
            "faces": faces,
            "meshes": meshes,
            "summary": summary,
            "table2": {"mu_FL": table2.mu_fl, "sigma_FL": table2.sigma_fl, "mu_EL": table2.mu_el, "sigma_EL": table2.sigma_el},
        }));
    }
    let line = |label: &str, triangles: &str, values: &mut dyn Iterator<Item = String>| {
        let values: Vec<String> = values.collect();
        outln!("{label:<24} {triangles:>9} {}", values.join(" "))
    };
    outln!("library {source} (at most {faces} faces)")?;
    line("mesh", "triangles", &mut LIBRARY_COLUMNS.iter().map(|(_, heading, _)| format!("{heading:>10}")))?;
    for (name, triangles, a) in &rows {
        line(
            name,
            &triangles.to_string(),
            &mut LIBRARY_COLUMNS.iter().map(|(_, _, value)| format!("{:>10.3}", value(a))),
        )?;
    }
    line("mean", "", &mut summary.iter().map(|(mean, _)| format!("{mean:>10.3}")))?;
    line("standard deviation", "", &mut summary.iter().map(|(_, std)| format!("{std:>10.3}")))?;
    line("Table 2 (Rhine)", "", &mut [table2.mu_fl, table2.mu_el].iter().map(|m| format!("{m:>10.3}")))?;
    outln!(
        "Table 2: the paper's 63 scans (standard deviations {:.3}, {:.3}). sphericity: Wadell's, of the mesh and of its mass-equivalent ellipsoid (Appendix A); relative: their ratio, 1 for an ellipsoid and lower the more angular the grain at its form; volume: the mesh's over that ellipsoid's; facet: the share of the surface on the largest flat facet with the form removed (stretched to L = I = S; triangles joined across edges, normals within 3°); farthest: the farthest vertex from the centre with the form removed, in semi-axes of that ellipsoid (3/√5 = 1.342 for a box)",
        table2.sigma_fl,
        table2.sigma_el
    )?;
    Ok(())
}

/// Mean and sample standard deviation (0 for a single value).
fn mean_std(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = if values.len() > 1 { values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0) } else { 0.0 };
    (mean, var.sqrt())
}
