//! Form distributions of §7.1: flatness and elongation drawn independently from normal
//! distributions, redrawn outside [0.1, 1], and the equancy statistics of §7.3.

use rand::Rng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::form::FormParameters;

/// Admissible flatness and elongation: capped below at 0.1 to avoid unrealistically flat or
/// elongated grains, and at most 1 by definition (§7.1).
pub const FORM_FACTOR_MIN: f64 = 0.1;
pub const FORM_FACTOR_MAX: f64 = 1.0;

/// Largest standard deviation accepted: with μ in [0.1, 1] it keeps the acceptance rate of the
/// redrawing above 30 %.
pub const SIGMA_MAX: f64 = 1.0;

#[derive(Debug, Error, PartialEq)]
pub enum DistributionError {
    #[error("{name} = {value} is out of range: a mean flatness or elongation must lie in [0.1, 1]")]
    Mean { name: &'static str, value: f64 },
    #[error("{name} = {value} is out of range: a standard deviation must lie in [0, 1]")]
    Sigma { name: &'static str, value: f64 },
}

/// The form distribution of the Rhine gravel (Table 2): μ_FL, σ_FL, μ_EL, σ_EL.
pub const RHINE_FORMS: FormDistribution =
    FormDistribution { mu_fl: 0.647, sigma_fl: 0.175, mu_el: 0.682, sigma_el: 0.139 };

/// Independent normal distributions of flatness FL and elongation EL (nominal parameters, the
/// hatted μ̂, σ̂ of §7.1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FormDistribution {
    pub mu_fl: f64,
    pub sigma_fl: f64,
    pub mu_el: f64,
    pub sigma_el: f64,
}

/// Mean and standard deviation of FL, EL and EQ.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FormMoments {
    #[serde(rename = "mean_FL")]
    pub mean_fl: f64,
    #[serde(rename = "std_FL")]
    pub std_fl: f64,
    #[serde(rename = "mean_EL")]
    pub mean_el: f64,
    #[serde(rename = "std_EL")]
    pub std_el: f64,
    #[serde(rename = "mean_EQ")]
    pub mean_eq: f64,
    #[serde(rename = "std_EQ")]
    pub std_eq: f64,
}

impl FormDistribution {
    pub fn new(mu_fl: f64, sigma_fl: f64, mu_el: f64, sigma_el: f64) -> Result<Self, DistributionError> {
        for (name, value) in [("mu_fl", mu_fl), ("mu_el", mu_el)] {
            if !(FORM_FACTOR_MIN..=FORM_FACTOR_MAX).contains(&value) {
                return Err(DistributionError::Mean { name, value });
            }
        }
        for (name, value) in [("sigma_fl", sigma_fl), ("sigma_el", sigma_el)] {
            if !(0.0..=SIGMA_MAX).contains(&value) {
                return Err(DistributionError::Sigma { name, value });
            }
        }
        Ok(Self { mu_fl, sigma_fl, mu_el, sigma_el })
    }

    /// μ_EQ = μ_EL μ_FL and σ_EQ² = (μ_EL² + σ_EL²)(μ_FL² + σ_FL²) − μ_EL² μ_FL², valid for
    /// independent FL and EL (§7.3); from the nominal parameters, as the paper applies them.
    pub fn equancy_statistics(&self) -> (f64, f64) {
        let mu = self.mu_el * self.mu_fl;
        let second = (self.mu_el.powi(2) + self.sigma_el.powi(2)) * (self.mu_fl.powi(2) + self.sigma_fl.powi(2));
        (mu, (second - mu * mu).max(0.0).sqrt())
    }

    /// The moments the grains will actually have: those of the normals truncated to [0.1, 1] by
    /// the redrawing (the shift the paper notes in §7.1), by numerical integration.
    pub fn truncated_moments(&self) -> FormMoments {
        let (m1_fl, m2_fl) = truncated_normal_moments(self.mu_fl, self.sigma_fl);
        let (m1_el, m2_el) = truncated_normal_moments(self.mu_el, self.sigma_el);
        let (m1_eq, m2_eq) = (m1_fl * m1_el, m2_fl * m2_el);
        let std = |m1: f64, m2: f64| (m2 - m1 * m1).max(0.0).sqrt();
        FormMoments {
            mean_fl: m1_fl,
            std_fl: std(m1_fl, m2_fl),
            mean_el: m1_el,
            std_el: std(m1_el, m2_el),
            mean_eq: m1_eq,
            std_eq: std(m1_eq, m2_eq),
        }
    }

    /// A sampler of this distribution; the parameters are checked as by [`FormDistribution::new`],
    /// since the fields are public and a mean outside [0.1, 1] would never be drawn.
    pub fn sampler(&self) -> Result<FormSampler, DistributionError> {
        let d = Self::new(self.mu_fl, self.sigma_fl, self.mu_el, self.sigma_el)?;
        let normal =
            |name, mu, sigma| Normal::new(mu, sigma).map_err(|_| DistributionError::Sigma { name, value: sigma });
        Ok(FormSampler { fl: normal("sigma_fl", d.mu_fl, d.sigma_fl)?, el: normal("sigma_el", d.mu_el, d.sigma_el)? })
    }
}

/// Draws (FL, EL) pairs and turns them into forms of a given size with Eqs. 20–22.
#[derive(Debug, Clone, Copy)]
pub struct FormSampler {
    fl: Normal<f64>,
    el: Normal<f64>,
}

impl FormSampler {
    /// FL then EL, each redrawn until it lies in [0.1, 1].
    pub fn sample_flatness_elongation<R: Rng + ?Sized>(&self, rng: &mut R) -> (f64, f64) {
        (draw_admissible(&self.fl, rng), draw_admissible(&self.el, rng))
    }

    pub fn sample<R: Rng + ?Sized>(&self, size: f64, rng: &mut R) -> FormParameters {
        let (fl, el) = self.sample_flatness_elongation(rng);
        FormParameters::from_flatness_elongation(fl, el, size)
    }
}

fn draw_admissible<R: Rng + ?Sized>(normal: &Normal<f64>, rng: &mut R) -> f64 {
    loop {
        let x = normal.sample(rng);
        if (FORM_FACTOR_MIN..=FORM_FACTOR_MAX).contains(&x) {
            return x;
        }
    }
}

/// First and second raw moments of N(μ, σ) truncated to [0.1, 1], by composite Simpson's rule.
fn truncated_normal_moments(mu: f64, sigma: f64) -> (f64, f64) {
    if sigma == 0.0 {
        return (mu, mu * mu);
    }
    // At least 20 nodes per σ so that narrow distributions are resolved; an even count.
    let intervals = 2 * ((10.0 * (FORM_FACTOR_MAX - FORM_FACTOR_MIN) / sigma).ceil() as usize).clamp(2000, 1_000_000);
    let h = (FORM_FACTOR_MAX - FORM_FACTOR_MIN) / intervals as f64;
    let mut m = [0.0; 3];
    for k in 0..=intervals {
        let x = FORM_FACTOR_MIN + k as f64 * h;
        let weight = if k == 0 || k == intervals {
            1.0
        } else if k % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let density = (-0.5 * ((x - mu) / sigma).powi(2)).exp();
        m[0] += weight * density;
        m[1] += weight * density * x;
        m[2] += weight * density * x * x;
    }
    (m[1] / m[0], m[2] / m[0])
}
