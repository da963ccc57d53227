//! Form parameters L ≥ I ≥ S, the grain size D (Eq. 1) and the 13 form factors of Table 1.

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Relative tolerance under which two axes count as equal when a form factor divides by their
/// difference (DRI and OPI divide by L − S, the inverse of DRI by L − I).
pub const EQUAL_AXES_TOLERANCE: f64 = 1e-9;

#[derive(Debug, Error, PartialEq)]
pub enum FormError {
    #[error("form parameters must be finite and positive, got L = {l}, I = {i}, S = {s}")]
    NotPositive { l: f64, i: f64, s: f64 },
    #[error("form parameters must satisfy L ≥ I ≥ S, got L = {l}, I = {i}, S = {s}")]
    NotOrdered { l: f64, i: f64, s: f64 },
}

/// The long, intermediate and short axes of a grain (full axes of its mass-equivalent ellipsoid,
/// Appendix A), in metres or in any consistent unit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FormParameters {
    #[serde(rename = "L")]
    pub l: f64,
    #[serde(rename = "I")]
    pub i: f64,
    #[serde(rename = "S")]
    pub s: f64,
}

impl FormParameters {
    /// Checked constructor: all three finite and positive, L ≥ I ≥ S.
    pub fn new(l: f64, i: f64, s: f64) -> Result<Self, FormError> {
        if !(l.is_finite() && i.is_finite() && s.is_finite() && l > 0.0 && i > 0.0 && s > 0.0) {
            return Err(FormError::NotPositive { l, i, s });
        }
        if l < i || i < s {
            return Err(FormError::NotOrdered { l, i, s });
        }
        Ok(Self { l, i, s })
    }

    /// Sorts three positive axes into L ≥ I ≥ S.
    pub fn from_unsorted(axes: [f64; 3]) -> Result<Self, FormError> {
        let mut a = axes;
        a.sort_by(|x, y| y.total_cmp(x));
        Self::new(a[0], a[1], a[2])
    }

    /// The form of a grain of size D with flatness FL and elongation EL: Eqs. 20–22.
    pub fn from_flatness_elongation(fl: f64, el: f64, d: f64) -> Self {
        let i = (2.0 / (1.0 + fl * fl)).sqrt() * d;
        Self { l: i / el, i, s: fl * i }
    }

    /// Sieve size D = sqrt((S² + I²)/2), Eq. 1.
    pub fn size(&self) -> f64 {
        ((self.s * self.s + self.i * self.i) / 2.0).sqrt()
    }

    /// Volume of the ellipsoid whose full axes are L, I, S.
    pub fn ellipsoid_volume(&self) -> f64 {
        std::f64::consts::PI * self.l * self.i * self.s / 6.0
    }

    /// The same form scaled to size `d` (Eq. 1).
    pub fn scaled_to_size(&self, d: f64) -> Self {
        let k = d / self.size();
        Self { l: self.l * k, i: self.i * k, s: self.s * k }
    }

    pub fn factors(&self) -> FormFactors {
        FormFactors::of(self)
    }
}

/// The form factors of Table 1, in the table's order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum FormFactor {
    FL,
    EL,
    EQ,
    ASF,
    CSF,
    DRI,
    IFI,
    IRI,
    JFF,
    KIS,
    MPS,
    OPI,
    WFI,
}

impl FormFactor {
    pub const ALL: [FormFactor; 13] = [
        FormFactor::FL,
        FormFactor::EL,
        FormFactor::EQ,
        FormFactor::ASF,
        FormFactor::CSF,
        FormFactor::DRI,
        FormFactor::IFI,
        FormFactor::IRI,
        FormFactor::JFF,
        FormFactor::KIS,
        FormFactor::MPS,
        FormFactor::OPI,
        FormFactor::WFI,
    ];

    /// The abbreviation of Table 1, used as JSON key and column name.
    pub fn symbol(self) -> &'static str {
        match self {
            FormFactor::FL => "FL",
            FormFactor::EL => "EL",
            FormFactor::EQ => "EQ",
            FormFactor::ASF => "ASF",
            FormFactor::CSF => "CSF",
            FormFactor::DRI => "DRI",
            FormFactor::IFI => "IFI",
            FormFactor::IRI => "IRI",
            FormFactor::JFF => "JFF",
            FormFactor::KIS => "KIS",
            FormFactor::MPS => "MPS",
            FormFactor::OPI => "OPI",
            FormFactor::WFI => "WFI",
        }
    }

    /// The name of Table 1.
    pub fn name(self) -> &'static str {
        match self {
            FormFactor::FL => "flatness",
            FormFactor::EL => "elongation",
            FormFactor::EQ => "equancy",
            FormFactor::ASF => "Aschenbrenner shape factor",
            FormFactor::CSF => "Corey shape factor",
            FormFactor::DRI => "disc-rod index",
            FormFactor::IFI => "Illenberger form index",
            FormFactor::IRI => "Illenberger rod index",
            FormFactor::JFF => "Janke form factor",
            FormFactor::KIS => "Krumbein intercept sphericity",
            FormFactor::MPS => "maximum projection sphericity",
            FormFactor::OPI => "oblate-prolate index",
            FormFactor::WFI => "Wentworth flatness index",
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// Why a form factor or its inverse has no value for a given form.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Undefined {
    /// DRI and OPI divide by L − S, which vanishes for L = S (a sphere-like form).
    EqualLongAndShort,
    /// The inverse of DRI divides by L − I.
    EqualLongAndIntermediate,
    /// The inverse of OPI divides by OPI, zero where DRI = 1/2.
    ZeroOpi,
}

impl Undefined {
    pub fn explain(self) -> &'static str {
        match self {
            Undefined::EqualLongAndShort => "undefined for L = S (division by L − S)",
            Undefined::EqualLongAndIntermediate => "undefined for L = I (DRI = 0)",
            Undefined::ZeroOpi => "undefined for DRI = 1/2 (OPI = 0)",
        }
    }
}

/// A form factor value, or the reason it has none.
pub type FactorValue = Result<f64, Undefined>;

/// All 13 Table 1 factors of one form and their inverses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FormFactors {
    values: [FactorValue; 13],
    inverses: [FactorValue; 13],
}

impl FormFactors {
    pub fn of(f: &FormParameters) -> Self {
        let (l, i, s) = (f.l, f.i, f.s);
        let long_minus_short = l - s;
        let sphere_like = long_minus_short <= EQUAL_AXES_TOLERANCE * l;
        let dri = if sphere_like { Err(Undefined::EqualLongAndShort) } else { Ok((l - i) / long_minus_short) };
        let opi = dri.map(|dri| 10.0 * (dri - 0.5) / (s / l));
        let values = [
            Ok(s / i),
            Ok(i / l),
            Ok(s / l),
            Ok(l * s / (i * i)),
            Ok(s / (l * i).sqrt()),
            dri,
            Ok((l + s) / i),
            Ok((s + i) / l),
            Ok(s / ((l * l + i * i + s * s) / 3.0).sqrt()),
            Ok((i * s / (l * l)).cbrt()),
            Ok((s * s / (l * i)).cbrt()),
            opi,
            Ok((l + i) / (2.0 * s)),
        ];
        let mut inverses = values.map(|v| v.map(|x| 1.0 / x));
        if dri.is_ok() && l - i <= EQUAL_AXES_TOLERANCE * l {
            inverses[FormFactor::DRI.index()] = Err(Undefined::EqualLongAndIntermediate);
        }
        if let Ok(dri) = dri
            && (dri - 0.5).abs() <= EQUAL_AXES_TOLERANCE
        {
            inverses[FormFactor::OPI.index()] = Err(Undefined::ZeroOpi);
        }
        Self { values, inverses }
    }

    pub fn get(&self, factor: FormFactor) -> FactorValue {
        self.values[factor.index()]
    }

    /// The inverse X⁻¹ of factor X (§6.3.1 adds all of them as features).
    pub fn inverse(&self, factor: FormFactor) -> FactorValue {
        self.inverses[factor.index()]
    }

    /// (factor, X, X⁻¹) in Table 1 order.
    pub fn iter(&self) -> impl Iterator<Item = (FormFactor, FactorValue, FactorValue)> + '_ {
        FormFactor::ALL.iter().map(|&f| (f, self.get(f), self.inverse(f)))
    }
}

/// Names of the 26 per-grain features in Table 1 order, each factor followed by its inverse:
/// "FL", "inv_FL", "EL", "inv_EL", … (§6.3.1).
pub fn feature_names() -> Vec<String> {
    FormFactor::ALL.iter().flat_map(|f| [f.symbol().to_string(), format!("inv_{}", f.symbol())]).collect()
}

/// Number-based mean and population standard deviation of one feature over a population.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FormStatistic {
    /// "FL", "inv_FL", … as in [`feature_names`].
    pub name: String,
    pub mean: f64,
    pub std: f64,
}

/// Statistics of the 26 features over the given forms, in [`feature_names`] order; a feature
/// undefined for any grain (e.g. DRI of a sphere) is left out.
pub fn form_statistics(forms: &[FormParameters]) -> Vec<FormStatistic> {
    let factors: Vec<FormFactors> = forms.iter().map(FormParameters::factors).collect();
    let mut out = Vec::new();
    for factor in FormFactor::ALL {
        for inverse in [false, true] {
            let values: Result<Vec<f64>, Undefined> =
                factors.iter().map(|f| if inverse { f.inverse(factor) } else { f.get(factor) }).collect();
            let Ok(values) = values else { continue };
            if values.is_empty() {
                continue;
            }
            let n = values.len() as f64;
            let mean = values.iter().sum::<f64>() / n;
            let variance = values.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
            let prefix = if inverse { "inv_" } else { "" };
            out.push(FormStatistic { name: format!("{prefix}{}", factor.symbol()), mean, std: variance.sqrt() });
        }
    }
    out
}
