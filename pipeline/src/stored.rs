//! The stored job: the JSON a job keeps in the database (and, for a Slurm task, in its job
//! folder), and the identity whose hash is its id. Its format is written out here type by type,
//! apart from the solver's types, so that changing those never changes a stored job or an id;
//! every value is concrete (the paper's rules already applied), so a job runs the same whatever
//! later versions take as defaults.
//!
//! - Format 1 is the JSON of sedpack 0.1.0, byte for byte. A mesh folder is its absolute path,
//!   so the id of such a job changed when the folder moved.
//! - Format 2 (this version's) is `{"job": IDENTITY, "mesh_folder": PATH or null}`. IDENTITY is
//!   format 1's JSON with a mesh folder named `folder` (its digest pins the meshes); the folder's
//!   place is `mesh_folder`, outside the id. IDENTITY is byte for byte format 1's JSON for every
//!   job without a mesh folder, so those ids are 0.1.0's.
//! - Format 3 is format 2 whose identity has fluid forces (`packing.fluid`), which formats 1 and
//!   2 have not: a job without them is still written in format 2, the same bytes and id as
//!   before, and a version that knows only formats 1 and 2 refuses a job with them instead of
//!   running it without.
//! - Format 4 is format 2 or 3 whose identity puts the contact point of polyhedra at EPA's
//!   witness (`packing.contact_point`, the rule of the paper's software), which formats 1 to 3
//!   have not: a job with the centre of pressure is written as before, and a version that knows
//!   only formats 1 to 3 refuses a job with the witness instead of running it with the centre.
//! - Format 5 is format 2, 3 or 4 whose identity creates every grain upright
//!   (`packing.process.orientation`, as the paper's software does), which formats 1 to 4 have
//!   not: a job of randomly turned grains is written as before, and a version that knows only
//!   formats 1 to 4 refuses a job of upright grains instead of turning them at random.
//! - Format 6 is format 2 to 5 whose identity creates new grains on the close-packed grid of the
//!   paper's software (`packing.process.grid`), which formats 1 to 5 have not: a job on the cubic
//!   grid is written as before, and a version that knows only formats 1 to 5 refuses a job on
//!   the close-packed grid instead of raining it from the cubic one.
//!
//! A stored format is frozen: a release that adds a field writes a new format with its own types
//! beside these, keeps reading every older one (giving the new field the value that reproduces
//! the older behaviour) and keeps the identity of jobs that leave the field at that value.

use anyhow::{Context, bail};
use nalgebra::Vector3;
use sha2::{Digest, Sha256};
use solver::dem::{Calibration, ContactPoint, Domain, Material, Shaking};
use solver::fluid::flow::Flow;
use solver::grain::{FormDistribution, MeshLibrary, SieveCurve, Table3Case};
use solver::packing::{FluidSpec, FormSpec, GrainSpec, Grid, Orientation, PackingSpec, Process, ShapeKind};

use crate::meshes;
use crate::spec::JobSpec;

/// The newest format this version reads and writes.
pub const FORMAT: u32 = 6;

/// The format a job is written in: the oldest of this version's that holds it.
pub fn format(job: &JobSpec) -> u32 {
    let p = &job.packing;
    needed(
        p.process.grid == Grid::Hcp,
        p.process.orientation == Orientation::Upright,
        p.contact_point == ContactPoint::Witness,
        p.fluid.is_some(),
    )
}

/// The oldest format with the close-packed grid, upright grains, a witness contact point and
/// fluid forces if these are present.
fn needed(hcp: bool, upright: bool, witness: bool, fluid: bool) -> u32 {
    match (hcp, upright, witness, fluid) {
        (true, ..) => 6,
        (false, true, ..) => 5,
        (false, false, true, _) => 4,
        (false, false, false, true) => 3,
        (false, false, false, false) => 2,
    }
}
/// A mesh folder's name in a format 2 identity.
const FOLDER: &str = "folder";

/// Format 1, the JSON of sedpack 0.1.0.
mod v1 {
    use serde::{Deserialize, Serialize};

    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    pub(super) struct Job {
        pub(super) name: String,
        /// The Table 3 case of the sieve curve, or "custom".
        pub(super) size_case: String,
        pub(super) packing: Packing,
        pub(super) experiment: Option<Experiment>,
    }

    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    pub(super) struct Packing {
        pub(super) domain: Domain,
        pub(super) height: f64,
        pub(super) grains: Grains,
        pub(super) material: Material,
        pub(super) time_step: f64,
        pub(super) calibration: Calibration,
        pub(super) process: Process,
        pub(super) slice: f64,
        pub(super) cutoff: f64,
        pub(super) trim: Option<f64>,
        pub(super) seed: u64,
        /// Format 3 only; absent, it leaves the bytes of formats 1 and 2 as they were.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub(super) fluid: Option<Fluid>,
        /// Format 4 only; absent (the centre of pressure), it leaves the bytes of formats 1 to 3
        /// as they were.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub(super) contact_point: Option<ContactPoint>,
    }

    /// A contact point other than the centre of pressure, the only one formats 1 to 3 know.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    pub(super) enum ContactPoint {
        Witness,
    }

    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    pub(super) struct Fluid {
        pub(super) viscosity: f64,
        pub(super) flow: Flow,
        pub(super) lift: bool,
        pub(super) cell: f64,
        /// Absent in jobs stored before it was a key, which updated their fluid forces every
        /// time step.
        #[serde(default)]
        pub(super) coupling: Option<f64>,
    }

    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    pub(super) enum Flow {
        Quiescent,
        Uniform { velocity: [f64; 3] },
        Laminar { shear_velocity: f64, depth: f64 },
        Logarithmic { shear_velocity: f64, roughness: f64 },
    }

    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    pub(super) enum Domain {
        Periodic { width: f64 },
        Cylinder { diameter: f64 },
    }

    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    pub(super) struct Grains {
        pub(super) shape: Shape,
        pub(super) size: Size,
        pub(super) mass: f64,
        pub(super) form: Form,
        pub(super) meshes: Option<Meshes>,
    }

    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    pub(super) enum Shape {
        Sphere,
        Ellipsoid,
        BondedSpheres,
        Mesh,
    }

    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    pub(super) struct Size {
        pub(super) sieves: Vec<f64>,
        pub(super) fractions: Vec<f64>,
    }

    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    pub(super) enum Form {
        Single { fl: f64, el: f64 },
        Distribution(Distribution),
        Own,
    }

    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    pub(super) struct Distribution {
        pub(super) mu_fl: f64,
        pub(super) sigma_fl: f64,
        pub(super) mu_el: f64,
        pub(super) sigma_el: f64,
    }

    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    pub(super) struct Meshes {
        pub(super) source: String,
        pub(super) faces: usize,
        pub(super) digest: String,
    }

    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    pub(super) struct Material {
        pub(super) density: f64,
        pub(super) fluid_density: f64,
        /// g: gravity is (0, 0, −g).
        pub(super) gravity: f64,
        pub(super) restitution: f64,
        pub(super) collision_time: f64,
        pub(super) poisson_ratio: f64,
        pub(super) friction: f64,
    }

    /// The discrete calibration repeats the time step, which must equal `time_step`.
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    pub(super) enum Calibration {
        Continuous,
        Discrete { time_step: f64 },
    }

    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    pub(super) struct Process {
        pub(super) spacing: f64,
        pub(super) velocity: f64,
        pub(super) shaking: Shaking,
        pub(super) shaking_duration: f64,
        pub(super) damping: f64,
        pub(super) height_change: f64,
        pub(super) interval: f64,
        pub(super) max_time: f64,
        /// Format 5 only; absent (turned at random), it leaves the bytes of formats 1 to 4 as
        /// they were.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub(super) orientation: Option<Orientation>,
        /// Format 6 only; absent (the cubic grid), it leaves the bytes of formats 1 to 5 as
        /// they were.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub(super) grid: Option<Grid>,
    }

    /// A grid of new grains other than the cubic one, the only one formats 1 to 5 know.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    pub(super) enum Grid {
        Hcp,
    }

    /// An orientation of new grains other than random, the only one formats 1 to 4 know.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    pub(super) enum Orientation {
        Upright,
    }

    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    pub(super) struct Shaking {
        pub(super) amplitude: f64,
        pub(super) period: f64,
    }

    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    pub(super) struct Experiment {
        pub(super) porosity: f64,
        pub(super) std: Option<f64>,
    }
}

/// Formats 2 to 6: format 1's job with the place of its mesh folder taken out of it.
mod v2 {
    use serde::{Deserialize, Serialize};

    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub(super) struct Job {
        /// Format 1's job with a mesh folder named `folder`: what the id hashes.
        pub(super) job: super::v1::Job,
        /// The mesh folder's absolute path when the job was (last) submitted.
        pub(super) mesh_folder: Option<String>,
    }
}

/// The stored JSON of a job, in its [`format`].
pub fn encode(job: &JobSpec) -> serde_json::Value {
    let mesh_folder = job.packing.grains.meshes.as_ref().map(|m| m.source.clone()).filter(|s| !meshes::is_builtin(s));
    serde_json::to_value(v2::Job { job: identity(job), mesh_folder })
        .expect("the stored job is plain numbers, strings and lists")
}

/// The JSON the job id hashes: the job without the place of its mesh folder.
pub fn canonical_json(job: &JobSpec) -> String {
    serde_json::to_string(&identity(job)).expect("the stored job is plain numbers, strings and lists")
}

/// Stable id of a resolved job: the first 16 hex digits of the SHA-256 of its identity (which
/// includes the campaign name, so ids never collide across campaigns).
pub fn job_id(job: &JobSpec) -> String {
    let digest = Sha256::digest(canonical_json(job).as_bytes());
    digest.iter().take(8).map(|b| format!("{b:02x}")).collect()
}

/// The job a stored JSON of the given format describes. Its meshes, if any, are only named: the
/// caller loads them again.
pub fn decode(format: u32, json: &serde_json::Value) -> anyhow::Result<JobSpec> {
    let job = match format {
        1 => serde_json::from_value(json.clone()).context("the stored job is not format 1")?,
        2..=6 => {
            let v2::Job { mut job, mesh_folder } = serde_json::from_value(json.clone())
                .with_context(|| format!("the stored job is not format {format}"))?;
            let named = job.packing.grains.meshes.as_mut().map(|m| &mut m.source);
            match (named, mesh_folder) {
                (Some(source), Some(folder)) if source == FOLDER => *source = folder,
                (Some(source), None) if meshes::is_builtin(source) => {}
                (None, None) => {}
                (source, folder) => bail!(
                    "the stored job names its meshes {source:?} with the mesh folder {folder:?}: format 2 \
                     names a builtin library without a folder, or `{FOLDER}` with one"
                ),
            }
            job
        }
        _ => bail!(
            "the job is stored in format {format}, which this version of sedpack (formats 1 to {FORMAT}) \
             cannot read: a newer sedpack stored it"
        ),
    };
    let p = &job.packing;
    let wanted =
        needed(p.process.grid.is_some(), p.process.orientation.is_some(), p.contact_point.is_some(), p.fluid.is_some());
    if wanted != format && !(format == 1 && wanted == 2) {
        bail!(
            "the stored job is not format {format}: format 3 is the one with fluid forces, format 4 the one \
             with EPA's witness as the contact point of polyhedra, format 5 the one with upright grains, format 6 \
             the one with the close-packed grid"
        );
    }
    from_v1(job)
}

fn from_v1(job: v1::Job) -> anyhow::Result<JobSpec> {
    let p = job.packing;
    let time_step = p.time_step;
    let calibration = match p.calibration {
        v1::Calibration::Continuous => Calibration::Continuous,
        v1::Calibration::Discrete { time_step: t } if t == time_step => Calibration::Discrete,
        v1::Calibration::Discrete { time_step: t } => {
            bail!("the stored job calibrates its contacts for a time step of {t} s but steps with {time_step} s")
        }
    };
    let size = match job.size_case.as_str() {
        "custom" => SieveCurve::new(p.grains.size.sieves, p.grains.size.fractions)?,
        name => {
            let curve = Table3Case::find(name).with_context(|| format!("unknown size case {name:?}"))?.sieve_curve();
            if (curve.sieves(), curve.fractions()) != (&p.grains.size.sieves[..], &p.grains.size.fractions[..]) {
                bail!("the stored sieve curve is not that of size case {name}");
            }
            curve
        }
    };
    let packing = PackingSpec {
        domain: match p.domain {
            v1::Domain::Periodic { width } => Domain::Periodic { width },
            v1::Domain::Cylinder { diameter } => Domain::Cylinder { diameter },
        },
        height: Some(p.height),
        grains: GrainSpec {
            shape: match p.grains.shape {
                v1::Shape::Sphere => ShapeKind::Sphere,
                v1::Shape::Ellipsoid => ShapeKind::Ellipsoid,
                v1::Shape::BondedSpheres => ShapeKind::BondedSpheres,
                v1::Shape::Mesh => ShapeKind::Mesh,
            },
            size,
            mass: p.grains.mass,
            form: match p.grains.form {
                v1::Form::Single { fl, el } => FormSpec::Single { fl, el },
                v1::Form::Distribution(d) => FormSpec::Distribution(FormDistribution {
                    mu_fl: d.mu_fl,
                    sigma_fl: d.sigma_fl,
                    mu_el: d.mu_el,
                    sigma_el: d.sigma_el,
                }),
                v1::Form::Own => FormSpec::Own,
            },
            meshes: p.grains.meshes.map(|m| MeshLibrary {
                source: m.source,
                faces: m.faces,
                digest: m.digest,
                meshes: Vec::new(),
            }),
        },
        material: Material {
            density: p.material.density,
            fluid_density: p.material.fluid_density,
            gravity: Vector3::new(0.0, 0.0, -p.material.gravity),
            restitution: p.material.restitution,
            collision_time: p.material.collision_time,
            poisson_ratio: p.material.poisson_ratio,
            friction: p.material.friction,
        },
        time_step,
        calibration,
        contact_point: match p.contact_point {
            None => ContactPoint::CentreOfPressure,
            Some(v1::ContactPoint::Witness) => ContactPoint::Witness,
        },
        process: Process {
            spacing: Some(p.process.spacing),
            velocity: p.process.velocity,
            orientation: match p.process.orientation {
                None => Orientation::Random,
                Some(v1::Orientation::Upright) => Orientation::Upright,
            },
            grid: match p.process.grid {
                None => Grid::Cubic,
                Some(v1::Grid::Hcp) => Grid::Hcp,
            },
            shaking: Shaking { amplitude: p.process.shaking.amplitude, period: p.process.shaking.period },
            shaking_duration: p.process.shaking_duration,
            damping: p.process.damping,
            height_change: p.process.height_change,
            interval: p.process.interval,
            max_time: Some(p.process.max_time),
        },
        slice: p.slice,
        cutoff: p.cutoff,
        trim: p.trim,
        seed: p.seed,
        fluid: p.fluid.map(|f| FluidSpec {
            viscosity: f.viscosity,
            flow: match f.flow {
                v1::Flow::Quiescent => Flow::Quiescent,
                v1::Flow::Uniform { velocity } => Flow::Uniform { velocity: Vector3::from(velocity) },
                v1::Flow::Laminar { shear_velocity, depth } => Flow::Laminar { shear_velocity, depth },
                v1::Flow::Logarithmic { shear_velocity, roughness } => Flow::Logarithmic { shear_velocity, roughness },
            },
            lift: f.lift,
            cell: Some(f.cell),
            coupling: Some(f.coupling.unwrap_or(time_step)),
        }),
    };
    packing.check().context("the stored job")?;
    let experiment = job.experiment.map(|e| analysis::Experiment { porosity: e.porosity, std: e.std });
    Ok(JobSpec { name: job.name, packing, experiment })
}

/// The job in format 1's types, a mesh folder named `folder`.
fn identity(job: &JobSpec) -> v1::Job {
    let spec = &job.packing;
    let derived = spec.derived();
    let grains = &spec.grains;
    let m = &spec.material;
    let p = &spec.process;
    v1::Job {
        name: job.name.clone(),
        size_case: grains.size.case().map_or("custom", |c| c.name).to_string(),
        packing: v1::Packing {
            domain: match spec.domain {
                Domain::Periodic { width } => v1::Domain::Periodic { width },
                Domain::Cylinder { diameter } => v1::Domain::Cylinder { diameter },
            },
            height: derived.height,
            grains: v1::Grains {
                shape: match grains.shape {
                    ShapeKind::Sphere => v1::Shape::Sphere,
                    ShapeKind::Ellipsoid => v1::Shape::Ellipsoid,
                    ShapeKind::BondedSpheres => v1::Shape::BondedSpheres,
                    ShapeKind::Mesh => v1::Shape::Mesh,
                },
                size: v1::Size { sieves: grains.size.sieves().to_vec(), fractions: grains.size.fractions().to_vec() },
                mass: grains.mass,
                form: match grains.form {
                    FormSpec::Single { fl, el } => v1::Form::Single { fl, el },
                    FormSpec::Distribution(d) => v1::Form::Distribution(v1::Distribution {
                        mu_fl: d.mu_fl,
                        sigma_fl: d.sigma_fl,
                        mu_el: d.mu_el,
                        sigma_el: d.sigma_el,
                    }),
                    FormSpec::Own => v1::Form::Own,
                },
                meshes: grains.meshes.as_ref().map(|l| v1::Meshes {
                    source: if meshes::is_builtin(&l.source) { l.source.clone() } else { FOLDER.into() },
                    faces: l.faces,
                    digest: l.digest.clone(),
                }),
            },
            material: v1::Material {
                density: m.density,
                fluid_density: m.fluid_density,
                gravity: -m.gravity.z,
                restitution: m.restitution,
                collision_time: m.collision_time,
                poisson_ratio: m.poisson_ratio,
                friction: m.friction,
            },
            time_step: spec.time_step,
            calibration: match spec.calibration {
                Calibration::Continuous => v1::Calibration::Continuous,
                Calibration::Discrete => v1::Calibration::Discrete { time_step: spec.time_step },
            },
            process: v1::Process {
                spacing: derived.spacing,
                velocity: p.velocity,
                shaking: v1::Shaking { amplitude: p.shaking.amplitude, period: p.shaking.period },
                shaking_duration: p.shaking_duration,
                damping: p.damping,
                height_change: p.height_change,
                interval: p.interval,
                max_time: derived.max_time,
                orientation: match p.orientation {
                    Orientation::Random => None,
                    Orientation::Upright => Some(v1::Orientation::Upright),
                },
                grid: match p.grid {
                    Grid::Cubic => None,
                    Grid::Hcp => Some(v1::Grid::Hcp),
                },
            },
            slice: spec.slice,
            cutoff: spec.cutoff,
            trim: spec.trim,
            seed: spec.seed,
            fluid: spec.fluid.map(|f| v1::Fluid {
                viscosity: f.viscosity,
                flow: match f.flow {
                    Flow::Quiescent => v1::Flow::Quiescent,
                    Flow::Uniform { velocity } => v1::Flow::Uniform { velocity: velocity.into() },
                    Flow::Laminar { shear_velocity, depth } => v1::Flow::Laminar { shear_velocity, depth },
                    Flow::Logarithmic { shear_velocity, roughness } => {
                        v1::Flow::Logarithmic { shear_velocity, roughness }
                    }
                },
                lift: f.lift,
                cell: derived.fluid_cell,
                coupling: Some(derived.fluid_coupling),
            }),
            contact_point: match spec.contact_point {
                ContactPoint::CentreOfPressure => None,
                ContactPoint::Witness => Some(v1::ContactPoint::Witness),
            },
        },
        experiment: job.experiment.map(|e| v1::Experiment { porosity: e.porosity, std: e.std }),
    }
}

#[cfg(test)]
mod tests {
    use solver::grain::MeshLibrary;
    use solver::packing::{DomainKind, FLUID_COUPLING};

    use super::*;

    fn job(packing: PackingSpec) -> JobSpec {
        JobSpec { name: "j".into(), packing, experiment: Some(analysis::Experiment { porosity: 0.37, std: None }) }
    }

    /// A job of meshes from a folder at `place`; its meshes are named, not loaded.
    fn folder_job(place: &str) -> JobSpec {
        let mut packing = PackingSpec::paper(DomainKind::Periodic);
        packing.grains.shape = ShapeKind::Mesh;
        packing.grains.form = FormSpec::Own;
        packing.grains.meshes =
            Some(MeshLibrary { source: place.into(), faces: 100, digest: "0123abcd".into(), meshes: Vec::new() });
        job(packing)
    }

    #[test]
    fn a_stored_job_reads_back_as_the_job_with_its_rules_applied() {
        let mut cylinder = PackingSpec::paper(DomainKind::Cylinder);
        cylinder.calibration = Calibration::Continuous;
        cylinder.trim = Some(0.002);
        for spec in [PackingSpec::paper(DomainKind::Periodic), cylinder] {
            let original = job(spec);
            let back = decode(format(&original), &encode(&original)).unwrap();
            assert_eq!(back.packing.derived(), original.packing.derived());
            assert_eq!(back.packing.height, Some(original.packing.derived().height));
            assert_eq!((back.name.as_str(), back.experiment), ("j", original.experiment));
            assert_eq!(canonical_json(&back), canonical_json(&original));
        }
    }

    #[test]
    fn a_job_without_a_mesh_folder_keeps_its_format_1_identity() {
        let original = job(PackingSpec::paper(DomainKind::Periodic));
        let stored = encode(&original);
        assert_eq!(stored["mesh_folder"], serde_json::Value::Null);
        assert_eq!(serde_json::to_string(&stored["job"]).unwrap(), canonical_json(&original));
        // Format 1 is the identity itself, and reads back as the same job.
        let v1: serde_json::Value = serde_json::from_str(&canonical_json(&original)).unwrap();
        assert_eq!(job_id(&decode(1, &v1).unwrap()), job_id(&original));
    }

    #[test]
    fn a_mesh_folder_moves_without_changing_the_id() {
        let (here, there) = (folder_job("/data/scans"), folder_job("/scratch/me/scans"));
        assert_eq!(job_id(&here), job_id(&there));
        let stored = encode(&there);
        assert_eq!(stored["job"]["packing"]["grains"]["meshes"]["source"], "folder");
        assert_eq!(stored["mesh_folder"], "/scratch/me/scans");
        let back = decode(2, &stored).unwrap();
        assert_eq!(back.packing.grains.meshes.unwrap().source, "/scratch/me/scans");
        // Another digest is another job.
        let mut other = folder_job("/data/scans");
        other.packing.grains.meshes.as_mut().unwrap().digest = "ffff".into();
        assert_ne!(job_id(&other), job_id(&here));
        // sedpack 0.1.0 stored the folder's path in the job (format 1): read back, it is the job
        // of the same identity.
        let mut v1 = stored["job"].clone();
        v1["packing"]["grains"]["meshes"]["source"] = "/old/place/scans".into();
        let old = decode(1, &v1).unwrap();
        assert_eq!(old.packing.grains.meshes.as_ref().unwrap().source, "/old/place/scans");
        assert_eq!(job_id(&old), job_id(&here));
    }

    #[test]
    fn a_job_with_fluid_forces_is_format_3_and_reads_back_with_its_cell_and_coupling_concrete() {
        let mut spec = PackingSpec::paper(DomainKind::Periodic);
        spec.fluid = Some(FluidSpec {
            flow: Flow::Logarithmic { shear_velocity: 0.05, roughness: 2e-4 },
            ..FluidSpec::STILL_WATER
        });
        let original = job(spec);
        assert_eq!(format(&original), 3);
        let stored = encode(&original);
        assert_eq!(stored["job"]["packing"]["fluid"]["cell"], serde_json::json!(original.packing.derived().fluid_cell));
        let back = decode(3, &stored).unwrap();
        assert_eq!(back.packing.fluid.map(|f| f.flow), original.packing.fluid.map(|f| f.flow));
        assert_eq!(canonical_json(&back), canonical_json(&original));
        assert_eq!(stored["job"]["packing"]["fluid"]["coupling"], serde_json::json!(FLUID_COUPLING));
        // Stored before the coupling was a key, a job updated its fluid forces every step.
        let mut before = stored.clone();
        before["job"]["packing"]["fluid"].as_object_mut().unwrap().remove("coupling");
        let every_step = decode(3, &before).unwrap().packing;
        assert_eq!(every_step.fluid.and_then(|f| f.coupling), Some(every_step.time_step));
        assert_eq!(every_step.fluid_forces().map(|f| f.coupling), Some(1));
        for older in [1, 2] {
            let json = if older == 1 { stored["job"].clone() } else { stored.clone() };
            let error = decode(older, &json).unwrap_err().to_string();
            assert!(error.contains("format 3 is the one with fluid forces"), "{error}");
        }
        // Without fluid forces the identity has no `fluid` key: format 1's bytes, format 2's id.
        let plain = job(PackingSpec::paper(DomainKind::Periodic));
        assert_eq!(format(&plain), 2);
        assert!(encode(&plain)["job"]["packing"].get("fluid").is_none());
    }

    #[test]
    fn a_job_with_the_witness_contact_point_is_format_4_and_the_centre_of_pressure_keeps_its_id() {
        let mut spec = PackingSpec::paper(DomainKind::Cylinder);
        spec.contact_point = ContactPoint::Witness;
        let original = job(spec);
        assert_eq!(format(&original), 4);
        let stored = encode(&original);
        assert_eq!(stored["job"]["packing"]["contact_point"], "Witness");
        let back = decode(4, &stored).unwrap();
        assert_eq!(back.packing.contact_point, ContactPoint::Witness);
        assert_eq!(canonical_json(&back), canonical_json(&original));
        let centre = job(PackingSpec::paper(DomainKind::Cylinder));
        assert_ne!(job_id(&original), job_id(&centre));
        // The centre of pressure is what formats 1 to 3 mean: no key, the same bytes and id.
        assert!(encode(&centre)["job"]["packing"].get("contact_point").is_none());
        assert_eq!(format(&centre), 2);
        // With fluid forces too it is still format 4; without the key, format 4 is refused.
        let mut both = original.clone();
        both.packing.fluid = Some(FluidSpec::STILL_WATER);
        assert_eq!(format(&both), 4);
        assert!(decode(4, &encode(&both)).unwrap().packing.fluid.is_some());
        for older in [2, 3] {
            let error = decode(older, &stored).unwrap_err().to_string();
            assert!(error.contains("format 4 the one with EPA's witness"), "{error}");
        }
        let error = decode(4, &encode(&centre)).unwrap_err().to_string();
        assert!(error.contains("not format 4"), "{error}");
    }

    #[test]
    fn a_job_of_upright_grains_is_format_5_and_random_turns_keep_their_id() {
        let mut spec = PackingSpec::paper(DomainKind::Cylinder);
        spec.process.orientation = Orientation::Upright;
        let original = job(spec);
        assert_eq!(format(&original), 5);
        let stored = encode(&original);
        assert_eq!(stored["job"]["packing"]["process"]["orientation"], "Upright");
        let back = decode(5, &stored).unwrap();
        assert_eq!(back.packing.process.orientation, Orientation::Upright);
        assert_eq!(canonical_json(&back), canonical_json(&original));
        let random = job(PackingSpec::paper(DomainKind::Cylinder));
        assert_ne!(job_id(&original), job_id(&random));
        // Random turns are what formats 1 to 4 mean: no key, the same bytes and id.
        assert!(encode(&random)["job"]["packing"]["process"].get("orientation").is_none());
        assert_eq!(format(&random), 2);
        // With the witness too it is format 5; a version reading it as format 4 refuses it.
        let mut both = original.clone();
        both.packing.contact_point = ContactPoint::Witness;
        assert_eq!(format(&both), 5);
        assert_eq!(decode(5, &encode(&both)).unwrap().packing.contact_point, ContactPoint::Witness);
        for older in [2, 4] {
            let error = decode(older, &stored).unwrap_err().to_string();
            assert!(error.contains("format 5 the one with upright grains"), "{error}");
        }
        let error = decode(5, &encode(&random)).unwrap_err().to_string();
        assert!(error.contains("not format 5"), "{error}");
    }

    #[test]
    fn a_job_on_the_close_packed_grid_is_format_6_and_the_cubic_grid_keeps_its_id() {
        let mut spec = PackingSpec::paper(DomainKind::Cylinder);
        spec.process.grid = Grid::Hcp;
        let original = job(spec);
        assert_eq!(format(&original), 6);
        let stored = encode(&original);
        assert_eq!(stored["job"]["packing"]["process"]["grid"], "Hcp");
        let back = decode(6, &stored).unwrap();
        assert_eq!(back.packing.process.grid, Grid::Hcp);
        assert_eq!(canonical_json(&back), canonical_json(&original));
        let cubic = job(PackingSpec::paper(DomainKind::Cylinder));
        assert_ne!(job_id(&original), job_id(&cubic));
        // The cubic grid is what formats 1 to 5 mean: no key, the same bytes and id.
        assert!(encode(&cubic)["job"]["packing"]["process"].get("grid").is_none());
        assert_eq!(format(&cubic), 2);
        // With upright grains and the witness too it is format 6; older formats refuse it.
        let mut all = original.clone();
        all.packing.contact_point = ContactPoint::Witness;
        all.packing.process.orientation = Orientation::Upright;
        assert_eq!(format(&all), 6);
        let back = decode(6, &encode(&all)).unwrap();
        assert_eq!((back.packing.process.orientation, back.packing.process.grid), (Orientation::Upright, Grid::Hcp));
        for older in [2, 4, 5] {
            let error = decode(older, &stored).unwrap_err().to_string();
            assert!(error.contains("format 6 the one with the close-packed grid"), "{error}");
        }
        let error = decode(6, &encode(&cubic)).unwrap_err().to_string();
        assert!(error.contains("not format 6"), "{error}");
    }

    #[test]
    fn stored_jobs_that_disagree_with_themselves_or_another_format_are_refused() {
        let stored = encode(&job(PackingSpec::paper(DomainKind::Periodic)));
        let error = decode(7, &stored).unwrap_err().to_string();
        assert!(error.contains("format 7") && error.contains("formats 1 to 6"), "{error}");
        let error = format!("{:#}", decode(1, &stored).unwrap_err());
        assert!(error.contains("not format 1"), "{error}");
        let error = decode(3, &stored).unwrap_err().to_string();
        assert!(error.contains("fluid forces"), "{error}");
        let mut two_steps = stored.clone();
        two_steps["job"]["packing"]["calibration"]["Discrete"]["time_step"] = serde_json::json!(1e-5);
        let error = decode(2, &two_steps).unwrap_err().to_string();
        assert!(error.contains("1e-5") || error.contains("0.00001"), "{error}");
        let mut renamed = stored.clone();
        renamed["job"]["size_case"] = serde_json::json!("U7");
        let error = decode(2, &renamed).unwrap_err().to_string();
        assert!(error.contains("size case U7"), "{error}");
        // A folder without its place, or a place without a folder.
        let mut placeless = encode(&folder_job("/data/scans"));
        placeless["mesh_folder"] = serde_json::Value::Null;
        let error = decode(2, &placeless).unwrap_err().to_string();
        assert!(error.contains("\"folder\"") && error.contains("None"), "{error}");
        let mut stray = stored;
        stray["mesh_folder"] = "/data/scans".into();
        assert!(decode(2, &stray).is_err());
    }
}
