//! Bonded-sphere grains of the second paper (Sun & Xiao, "Realistic representation of grain
//! shapes in CFD–DEM simulations of sediment transport: a bonded-sphere approach"): a grain with
//! full axes D_l ≥ D_i ≥ D_s is sorted into a Zingg class by D_i/D_l and D_s/D_i (§2.4, Fig. 2)
//! and represented by a few non-overlapping component spheres (§2.4, Fig. 3, Appendix), which
//! move as one rigid body.
//!
//! The construction is the paper's, read literally; where the text leaves a choice open the
//! choice and its reason are written at the place it is made (`ZinggClass::of`, `construction`).
//! It is not tuned to the paper's claim (§3, Fig. 5) that mass and moments of inertia fall
//! within 25 % of the ellipsoid with the same axes; `solver/tests/grain_bonded.rs` measures how
//! far they actually fall.

use std::f64::consts::PI;
use std::fmt;

use nalgebra::{Matrix3, Rotation3, Vector3};
use serde::{Deserialize, Serialize};

use super::ellipsoid::principal_frame;
use super::form::{FormError, FormParameters};
use super::mesh::MassProperties;

/// ε of the Appendix: two axes are "almost equal" when the shorter exceeds (1 − ε) times the longer.
pub const EQUANT_EPSILON: f64 = 0.1;

/// The Zingg class of a grain (§2.4, Fig. 2) and, for equant grains, the Appendix's subtype 1–4.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(try_from = "String", into = "&'static str")]
pub enum ZinggClass {
    Disk,
    Blade,
    Rod,
    /// Subtype 1 ≈ sphere (D_s ≈ D_i ≈ D_l), 2 (D_s ≈ D_i < D_l), 3 (D_s < D_i ≈ D_l),
    /// 4 (D_s < D_i < D_l); no other value is a class (`name` panics on one).
    Equant(u8),
}

impl ZinggClass {
    /// §2.4: D_i/D_l and D_s/D_i against 2/3 give disk (D_i > 2/3 D_l, D_s < 2/3 D_i), blade
    /// (both < 2/3), rod (D_i < 2/3 D_l, D_s > 2/3 D_i) and equant (both > 2/3); the Appendix
    /// splits equant grains by D_i/D_l and D_s/D_i against 1 − ε.
    ///
    /// The paper's inequalities are all strict, leaving a ratio of exactly 2/3 (or 1 − ε) in no
    /// class; such a tie goes to "much shorter" (blade/rod side of 2/3, not-almost-equal side of
    /// 1 − ε), because "similar" is the paper's open interval. The 2/3 test is written as
    /// 3·D_i > 2·D_l so that a tie such as (3, 2, ·) is decided exactly, not by rounding 2/3.
    pub fn of(form: &FormParameters) -> Self {
        let similar = |short: f64, long: f64| 3.0 * short > 2.0 * long;
        let almost_equal = |short: f64, long: f64| short > (1.0 - EQUANT_EPSILON) * long;
        let (l, i, s) = (form.l, form.i, form.s);
        match (similar(i, l), similar(s, i)) {
            (true, false) => ZinggClass::Disk,
            (false, false) => ZinggClass::Blade,
            (false, true) => ZinggClass::Rod,
            (true, true) => ZinggClass::Equant(match (almost_equal(i, l), almost_equal(s, i)) {
                (true, true) => 1,
                (false, true) => 2,
                (true, false) => 3,
                (false, false) => 4,
            }),
        }
    }

    /// "disk", "blade", "rod", "equant-1" … "equant-4".
    pub fn name(self) -> &'static str {
        match self {
            ZinggClass::Disk => "disk",
            ZinggClass::Blade => "blade",
            ZinggClass::Rod => "rod",
            ZinggClass::Equant(1) => "equant-1",
            ZinggClass::Equant(2) => "equant-2",
            ZinggClass::Equant(3) => "equant-3",
            ZinggClass::Equant(4) => "equant-4",
            ZinggClass::Equant(k) => unreachable!("equant subtype {k} outside 1–4"),
        }
    }

    /// All seven classes in the order of `name`'s list.
    pub const ALL: [ZinggClass; 7] = [
        ZinggClass::Disk,
        ZinggClass::Blade,
        ZinggClass::Rod,
        ZinggClass::Equant(1),
        ZinggClass::Equant(2),
        ZinggClass::Equant(3),
        ZinggClass::Equant(4),
    ];
}

impl fmt::Display for ZinggClass {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl From<ZinggClass> for &'static str {
    fn from(class: ZinggClass) -> Self {
        class.name()
    }
}

impl TryFrom<String> for ZinggClass {
    type Error = String;

    fn try_from(name: String) -> Result<Self, Self::Error> {
        ZinggClass::ALL
            .into_iter()
            .find(|c| c.name() == name)
            .ok_or_else(|| format!("unknown Zingg class {name:?} (expected disk, blade, rod, equant-1 … equant-4)"))
    }
}

/// One component sphere of a bonded grain.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ComponentSphere {
    pub center: Vector3<f64>,
    pub radius: f64,
}

impl ComponentSphere {
    pub fn volume(&self) -> f64 {
        4.0 / 3.0 * PI * self.radius.powi(3)
    }
}

/// Volume and principal moments of inertia (ascending, per unit density) of a solid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SolidMass {
    pub volume: f64,
    pub inertia: Vector3<f64>,
}

/// The ellipsoid with full axes L, I, S, the reference of the second paper's a-priori test
/// (§3, Fig. 5): volume π L I S/6, moments V (b² + c²)/5 … with semi-axes a ≥ b ≥ c, which are
/// ascending because the smallest moment is about the longest axis.
pub fn ellipsoid_mass(form: &FormParameters) -> SolidMass {
    let volume = form.ellipsoid_volume();
    let (a2, b2, c2) = ((form.l / 2.0).powi(2), (form.i / 2.0).powi(2), (form.s / 2.0).powi(2));
    SolidMass { volume, inertia: volume / 5.0 * Vector3::new(b2 + c2, a2 + c2, a2 + b2) }
}

/// A bonded-sphere grain as one rigid body, in its principal frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BondedGrain {
    /// The full axes the grain was built from.
    pub form: FormParameters,
    pub class: ZinggClass,
    /// Component spheres in the principal frame: centre of mass at the origin, x, y, z along the
    /// principal axes of the smallest, middle and largest moment.
    pub spheres: Vec<ComponentSphere>,
    /// Sum of the component spheres' volumes (they do not overlap).
    pub volume: f64,
    /// Principal moments of inertia about the centre of mass per unit density, ascending.
    pub inertia: Vector3<f64>,
    /// Radius of the smallest origin-centred sphere enclosing all component spheres.
    pub bounding_radius: f64,
    /// Proper rotation from the principal frame to the construction frame (x along D_l, y along
    /// D_i, z along D_s, origin at the centre of the spheres' bounding box):
    /// x_construction = rotation · x_principal + center_of_mass.
    pub rotation: Rotation3<f64>,
    /// The centre of mass in the construction frame.
    pub center_of_mass: Vector3<f64>,
}

impl BondedGrain {
    /// The grain's volume and principal moments, for comparison with `ellipsoid_mass`.
    pub fn mass(&self) -> SolidMass {
        SolidMass { volume: self.volume, inertia: self.inertia }
    }
}

/// The bonded-sphere grain of the second paper for full axes L ≥ I ≥ S (§2.4, Appendix):
/// `construction`'s spheres moved to the principal frame, with volume and inertia summed over the
/// spheres (§2.4 step 2: "straightforward for non-overlapping spheres").
pub fn bonded_grain(form: &FormParameters) -> Result<BondedGrain, FormError> {
    let (class, built) = construction(form)?;
    let props = sphere_mass_properties(&built);
    let (rotation, inertia) = principal_frame(&props.inertia);
    let com = props.center_of_mass;
    let spheres: Vec<ComponentSphere> = built
        .iter()
        .map(|c| ComponentSphere { center: rotation.inverse() * (c.center - com), radius: c.radius })
        .collect();
    let bounding_radius = spheres.iter().map(|c| c.center.norm() + c.radius).fold(0.0, f64::max);
    Ok(BondedGrain {
        form: *form,
        class,
        spheres,
        volume: props.volume,
        inertia,
        bounding_radius,
        rotation,
        center_of_mass: com,
    })
}

/// Volume, centre of mass and inertia tensor (per unit density, about the centre of mass) of a
/// union of non-overlapping spheres: each sphere's (2/5) V r² plus the parallel-axis term.
pub fn sphere_mass_properties(spheres: &[ComponentSphere]) -> MassProperties {
    let volume: f64 = spheres.iter().map(ComponentSphere::volume).sum();
    let center_of_mass = spheres.iter().map(|c| c.volume() * c.center).sum::<Vector3<f64>>() / volume;
    let inertia = spheres
        .iter()
        .map(|c| {
            let v = c.volume();
            let d = c.center - center_of_mass;
            Matrix3::identity() * (v * (0.4 * c.radius * c.radius + d.norm_squared())) - v * d * d.transpose()
        })
        .sum();
    MassProperties { volume, center_of_mass, inertia }
}

/// The paper's component spheres for full axes L ≥ I ≥ S, in the construction frame: x along
/// D_l, y along D_i, z along D_s, origin at the centre of the spheres' bounding box. The spheres
/// are not confined to the L × I × S box: rounding lengthens a row by up to d_p/2, a rod's
/// d_p = √(D_s D_i) exceeds D_s, a single equant sphere exceeds D_s (the tests give each extent).
///
/// - Disk and blade (§2.4, Fig. 3a, b): spheres of d_p = D_s in a hexagonal lattice of
///   n_l = [D_l/d_p] spheres along D_l and n_i = [D_i/d_p] along D_i. Choice: n_i touching
///   rows along D_l, d_p·√3/2 apart, holding n_l and n_l − 1 spheres alternately (the middle
///   row, for even n_i the upper middle row, holds n_l), each row centred so that neighbouring
///   rows sit in each other's gaps. This keeps the grain's extent along D_l at n_l·d_p, as for
///   the rod, where n_l spheres in every row would overhang by d_p/2: the paper's aim is to
///   preserve the axes (§2.4, last paragraph). For n_l = n_i = 3 it is the seven-sphere hexagon.
///   The paper gives no outline (such as an ellipse) to clip the lattice to, so none is applied.
/// - Rod (§2.4, Fig. 3c): n_l = [D_l/d_p] touching spheres of d_p = √(D_s D_i) in a row.
/// - Equant (Appendix, Fig. 3d): subtype 1 one sphere of d_p = (D_l D_i D_s)^(1/3); subtype 2 a
///   main sphere of √(D_s D_i) and an auxiliary of D_l − √(D_s D_i); subtype 3 a main sphere of
///   D_s and two auxiliaries of D_l − D_s at angle θ_e = 2 asin((D_i + D_s − D_l)/D_l);
///   subtype 4 a main sphere of D_s, two auxiliaries of (D_l − D_s)/2 on either side and a
///   third at θ_e = 2 asin((2D_i + D_s − D_l)/(D_l + D_s)) from the first. Choice: each
///   auxiliary touches the main sphere and θ_e is the angle at the main sphere's centre between
///   auxiliary centres, all in the D_l–D_i plane. The paper does not say so, but it is the
///   reading under which its numbers fit: main plus auxiliary then span exactly D_l along their
///   line (subtypes 2–4), and sin(θ_e/2) is (D_i − d_aux) over twice the touching centre
///   distance (D_l for subtype 3, (D_l + D_s)/2 for subtype 4), so the two auxiliaries at angle
///   θ_e have centres D_i − d_aux apart and outer surfaces exactly D_i apart along that line.
/// - [·] rounds to the nearest integer, halves away from zero (the paper does not say).
pub fn construction(form: &FormParameters) -> Result<(ZinggClass, Vec<ComponentSphere>), FormError> {
    // Checked again because the fields are public: a zero D_s would ask for infinitely many spheres.
    let FormParameters { l, i, s } = FormParameters::new(form.l, form.i, form.s)?;
    let class = ZinggClass::of(form);
    let sphere = |x: f64, y: f64, d: f64| ComponentSphere { center: Vector3::new(x, y, 0.0), radius: d / 2.0 };
    let mut spheres = match class {
        ZinggClass::Disk | ZinggClass::Blade => {
            let dp = s;
            let (nl, ni) = ((l / dp).round() as usize, (i / dp).round() as usize);
            let row_spacing = dp * 3f64.sqrt() / 2.0;
            let middle = ni / 2;
            (0..ni)
                .flat_map(|row| {
                    let y = (row as f64 - (ni as f64 - 1.0) / 2.0) * row_spacing;
                    let count = if (row + middle) % 2 == 0 { nl } else { nl - 1 };
                    (0..count).map(move |k| sphere((k as f64 - (count as f64 - 1.0) / 2.0) * dp, y, dp))
                })
                .collect()
        }
        ZinggClass::Rod => {
            let dp = (s * i).sqrt();
            let nl = (l / dp).round() as usize;
            (0..nl).map(|k| sphere((k as f64 - (nl as f64 - 1.0) / 2.0) * dp, 0.0, dp)).collect()
        }
        ZinggClass::Equant(1) => vec![sphere(0.0, 0.0, (l * i * s).cbrt())],
        ZinggClass::Equant(2) => {
            let main = (s * i).sqrt();
            let aux = l - main;
            vec![sphere(0.0, 0.0, main), sphere((main + aux) / 2.0, 0.0, aux)]
        }
        ZinggClass::Equant(3) => {
            let aux = l - s;
            let half_angle = ((i + s - l) / l).asin();
            let r = (s + aux) / 2.0;
            let (x, y) = (r * half_angle.cos(), r * half_angle.sin());
            vec![sphere(0.0, 0.0, s), sphere(x, y, aux), sphere(x, -y, aux)]
        }
        ZinggClass::Equant(_) => {
            let aux = (l - s) / 2.0;
            let angle = 2.0 * ((2.0 * i + s - l) / (l + s)).asin();
            let r = (s + aux) / 2.0;
            vec![
                sphere(0.0, 0.0, s),
                sphere(r, 0.0, aux),
                sphere(-r, 0.0, aux),
                sphere(r * angle.cos(), r * angle.sin(), aux),
            ]
        }
    };
    // Centre the bounding box on the origin, so the frame does not depend on where a layout starts.
    let lo = spheres.iter().fold(Vector3::repeat(f64::INFINITY), |m, c| m.inf(&c.center.add_scalar(-c.radius)));
    let hi = spheres.iter().fold(Vector3::repeat(f64::NEG_INFINITY), |m, c| m.sup(&c.center.add_scalar(c.radius)));
    let middle = (lo + hi) / 2.0;
    for c in &mut spheres {
        c.center -= middle;
    }
    Ok((class, spheres))
}
