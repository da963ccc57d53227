//! Grain sizes from sieve curves (§3.2): mass fractions per sieve class converted to number
//! weights with Eqs. 8–9, sampled on a logarithmic size scale so that no grain leaves its class.

use rand::{Rng, RngExt};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Sieve edges of the laboratory experiments (Table 3), in metres.
pub const TABLE3_SIEVES: [f64; 8] = [2.8e-3, 4.0e-3, 5.6e-3, 8.0e-3, 11.2e-3, 16.0e-3, 22.4e-3, 31.5e-3];

/// Tolerance on the sum of mass fractions.
pub const FRACTION_SUM_TOLERANCE: f64 = 1e-6;

/// One row of Table 3: a size case with its mass fractions, the measured porosity of the
/// laboratory experiments and the generation spacing h_g the paper used.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Table3Case {
    pub name: &'static str,
    pub fractions: [f64; 7],
    pub porosity: f64,
    pub porosity_std: f64,
    /// Generation spacing h_g in metres.
    pub spacing: f64,
}

pub const TABLE3: [Table3Case; 7] = [
    Table3Case {
        name: "U1",
        fractions: [0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0],
        porosity: 0.371,
        porosity_std: 0.001,
        spacing: 0.016,
    },
    Table3Case {
        name: "U3",
        fractions: [0.0, 0.0, 0.21, 0.58, 0.21, 0.0, 0.0],
        porosity: 0.356,
        porosity_std: 0.003,
        spacing: 0.022,
    },
    Table3Case {
        name: "U5",
        fractions: [0.0, 0.06, 0.24, 0.4, 0.24, 0.06, 0.0],
        porosity: 0.344,
        porosity_std: 0.002,
        spacing: 0.026,
    },
    Table3Case {
        name: "U7",
        fractions: [0.04, 0.11, 0.22, 0.26, 0.22, 0.11, 0.04],
        porosity: 0.315,
        porosity_std: 0.002,
        spacing: 0.022,
    },
    Table3Case {
        name: "B30",
        fractions: [0.08, 0.13, 0.08, 0.06, 0.18, 0.29, 0.18],
        porosity: 0.270,
        porosity_std: 0.003,
        spacing: 0.020,
    },
    Table3Case {
        name: "B50",
        fractions: [0.13, 0.21, 0.13, 0.06, 0.13, 0.21, 0.13],
        porosity: 0.289,
        porosity_std: 0.005,
        spacing: 0.020,
    },
    Table3Case {
        name: "B70",
        fractions: [0.18, 0.29, 0.18, 0.06, 0.08, 0.13, 0.08],
        porosity: 0.299,
        porosity_std: 0.002,
        spacing: 0.018,
    },
];

impl Table3Case {
    pub fn find(name: &str) -> Option<&'static Table3Case> {
        TABLE3.iter().find(|c| c.name.eq_ignore_ascii_case(name))
    }

    /// The case's sieve curve, which remembers the case.
    pub fn sieve_curve(&self) -> SieveCurve {
        let sieves = TABLE3_SIEVES.to_vec();
        SieveCurve { sieves, fractions: self.fractions.to_vec(), case: Some(self.name.to_string()) }
    }
}

#[derive(Debug, Error, PartialEq)]
pub enum SizeError {
    #[error("sieves: a sieve curve needs at least two sieves, got {0}")]
    TooFewSieves(usize),
    #[error("fractions: {fractions} mass fractions given for {sieves} sieves; expected one per class, i.e. {}", sieves - 1)]
    CountMismatch { sieves: usize, fractions: usize },
    #[error("sieves: sieve {index} is {value} m; sieves must be positive and strictly increasing")]
    Unsorted { index: usize, value: f64 },
    #[error("fractions: mass fraction {index} is {value}; fractions must be finite and ≥ 0")]
    NegativeFraction { index: usize, value: f64 },
    #[error("fractions: mass fractions sum to {0}, expected 1 (± 1e-6)")]
    Sum(f64),
    #[error("unknown size case '{0}': expected one of U1, U3, U5, U7, B30, B50, B70 or a sieve curve")]
    UnknownCase(String),
}

/// A sieve curve: sieve edges s_0 < s_1 < … < s_n (m) and the mass fraction of each class.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SieveCurve {
    sieves: Vec<f64>,
    fractions: Vec<f64>,
    /// The Table 3 case this curve is, when it was named as one.
    case: Option<String>,
}

impl SieveCurve {
    pub fn new(sieves: Vec<f64>, fractions: Vec<f64>) -> Result<Self, SizeError> {
        if sieves.len() < 2 {
            return Err(SizeError::TooFewSieves(sieves.len()));
        }
        if fractions.len() + 1 != sieves.len() {
            return Err(SizeError::CountMismatch { sieves: sieves.len(), fractions: fractions.len() });
        }
        for (index, &value) in sieves.iter().enumerate() {
            let previous = if index == 0 { 0.0 } else { sieves[index - 1] };
            if !(value.is_finite() && value > previous) {
                return Err(SizeError::Unsorted { index, value });
            }
        }
        if let Some((index, &value)) = fractions.iter().enumerate().find(|(_, m)| !(m.is_finite() && **m >= 0.0)) {
            return Err(SizeError::NegativeFraction { index, value });
        }
        let sum: f64 = fractions.iter().sum();
        if (sum - 1.0).abs() > FRACTION_SUM_TOLERANCE {
            return Err(SizeError::Sum(sum));
        }
        Ok(Self { sieves, fractions, case: None })
    }

    /// A Table 3 case by name (case-insensitive).
    pub fn preset(name: &str) -> Result<Self, SizeError> {
        Table3Case::find(name).map(Table3Case::sieve_curve).ok_or_else(|| SizeError::UnknownCase(name.into()))
    }

    pub fn sieves(&self) -> &[f64] {
        &self.sieves
    }

    pub fn fractions(&self) -> &[f64] {
        &self.fractions
    }

    pub fn classes(&self) -> usize {
        self.fractions.len()
    }

    /// The Table 3 case the curve was named as, if it was.
    pub fn case(&self) -> Option<&'static Table3Case> {
        Table3Case::find(self.case.as_deref()?)
    }

    /// The lower sieve of the first class with grains: no grain is smaller.
    pub fn smallest_in_use(&self) -> f64 {
        self.sieves[self.fractions.iter().position(|&f| f > 0.0).unwrap_or(0)]
    }

    /// The upper sieve of the last class with grains: no grain is larger.
    pub fn largest_in_use(&self) -> f64 {
        self.sieves[self.fractions.iter().rposition(|&f| f > 0.0).unwrap_or(self.classes() - 1) + 1]
    }

    /// The largest sieve, h_pd of §6.1.
    pub fn largest_sieve(&self) -> f64 {
        *self.sieves.last().expect("validated: at least two sieves")
    }

    /// Geometric mean d̄_i = sqrt(s_i s_{i+1}) of class i, Eq. 8.
    pub fn representative_diameter(&self, class: usize) -> f64 {
        (self.sieves[class] * self.sieves[class + 1]).sqrt()
    }

    /// The packing's grains per class as drawn, from each created grain's (class, mass in kg):
    /// every class the curve asks for or a grain fell in, in sieve order. §3.2 draws each grain's
    /// class at random, so a seed's mass fractions scatter around the curve's, most for a wide
    /// curve whose coarse classes hold few grains.
    pub fn drawn(&self, grains: impl IntoIterator<Item = (usize, f64)>) -> Vec<DrawnClass> {
        let mut classes: Vec<DrawnClass> = (0..self.classes())
            .map(|i| DrawnClass {
                lower: self.sieves[i],
                upper: self.sieves[i + 1],
                asked: self.fractions[i],
                grains: 0,
                mass: 0.0,
            })
            .collect();
        for (class, mass) in grains {
            classes[class].grains += 1;
            classes[class].mass += mass;
        }
        classes.retain(|c| c.asked > 0.0 || c.grains > 0);
        classes
    }

    /// Number of grains per class n_i = m_i m_tot / (ρ_p V̄_i) with V̄_i = π d̄_i³/6, Eq. 9.
    pub fn grain_numbers(&self, total_mass: f64, density: f64) -> Vec<f64> {
        (0..self.classes())
            .map(|i| {
                let volume = std::f64::consts::PI * self.representative_diameter(i).powi(3) / 6.0;
                self.fractions[i] * total_mass / (density * volume)
            })
            .collect()
    }

    /// Number weights of the classes (Eq. 9 normalised; m_tot and ρ_p cancel).
    pub fn number_weights(&self) -> Vec<f64> {
        let numbers = self.grain_numbers(1.0, 1.0);
        let total: f64 = numbers.iter().sum();
        numbers.into_iter().map(|n| n / total).collect()
    }

    pub fn sampler(&self) -> SizeSampler {
        let mut cumulative = Vec::with_capacity(self.classes());
        let mut sum = 0.0;
        for w in self.number_weights() {
            sum += w;
            cumulative.push(sum);
        }
        SizeSampler { log_sieves: self.sieves.iter().map(|s| s.ln()).collect(), cumulative }
    }
}

/// One sieve class of a finished packing: the grains created in it and their mass, beside the
/// mass fraction the sieve curve asked for.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DrawnClass {
    /// Lower sieve (m).
    pub lower: f64,
    /// Upper sieve (m).
    pub upper: f64,
    /// The curve's mass fraction of the class.
    pub asked: f64,
    pub grains: usize,
    /// Mass created in the class (kg).
    pub mass: f64,
}

/// Whether the curve behind a packing's drawn classes asks for more than one: only then can its
/// seeds draw different mixes.
pub fn graded(classes: &[DrawnClass]) -> bool {
    classes.iter().filter(|c| c.asked > 0.0).count() > 1
}

/// Each drawn class's share of the mass created, to set beside the curve's `asked`.
pub fn mass_shares(classes: &[DrawnClass]) -> Vec<f64> {
    let total: f64 = classes.iter().map(|c| c.mass).sum();
    classes.iter().map(|c| c.mass / total).collect()
}

impl DrawnClass {
    /// "5.6–8 mm", as the sieves are named.
    pub fn label(&self) -> String {
        format!("{}–{} mm", trimmed(1e3 * self.lower), trimmed(1e3 * self.upper))
    }
}

/// A number with at most two decimals and no trailing zeros: "21", "12.5", "5.6".
pub fn trimmed(x: f64) -> String {
    let text = format!("{x:.2}");
    text.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Draws grain sizes: a class by its number weight, then ln D uniform inside the class, which
/// makes the cumulative number curve piecewise linear in log D (§3.2).
#[derive(Debug, Clone)]
pub struct SizeSampler {
    log_sieves: Vec<f64>,
    cumulative: Vec<f64>,
}

impl SizeSampler {
    /// Returns (class index, size D in m).
    pub fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> (usize, f64) {
        let total = *self.cumulative.last().expect("at least one class");
        // Kept below the total so that rounding cannot select a trailing empty class.
        let u = (rng.random::<f64>() * total).min(total * (1.0 - f64::EPSILON));
        // The first class whose cumulative weight exceeds u; empty classes are never chosen.
        let class = self.cumulative.partition_point(|&c| c <= u);
        let (lo, hi) = (self.log_sieves[class], self.log_sieves[class + 1]);
        (class, (lo + rng.random::<f64>() * (hi - lo)).exp())
    }
}
