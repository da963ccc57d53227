//! `sedpack sample forms|sizes`: draw a population of grains as a packing would, and report it.

use std::path::Path;

use anyhow::Context;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use solver::grain::{FormDistribution, FormMoments, SieveCurve};

use crate::cli::{SampleFormsArgs, SampleSizesArgs};
use crate::outln;
use crate::output::{Table, number, print_json};

#[derive(Serialize)]
struct SampledForms {
    count: u64,
    seed: u64,
    #[serde(flatten)]
    sampled: FormMoments,
    /// Moments of the truncated normals the sample is drawn from.
    expected: FormMoments,
}

pub fn forms(args: &SampleFormsArgs) -> anyhow::Result<()> {
    let d = &args.distribution;
    let dist = FormDistribution::new(d.mu_fl, d.sigma_fl, d.mu_el, d.sigma_el)?;
    let sampler = dist.sampler()?;
    let mut rng = ChaCha8Rng::seed_from_u64(args.draw.seed);
    let (mut fl, mut el, mut eq) = (Moments::default(), Moments::default(), Moments::default());
    for _ in 0..args.draw.count {
        let (f, e) = sampler.sample_flatness_elongation(&mut rng);
        fl.add(f);
        el.add(e);
        eq.add(f * e);
    }
    let sampled = FormMoments {
        mean_fl: fl.mean(),
        std_fl: fl.std(),
        mean_el: el.mean(),
        std_el: el.std(),
        mean_eq: eq.mean(),
        std_eq: eq.std(),
    };
    let result =
        SampledForms { count: args.draw.count, seed: args.draw.seed, sampled, expected: dist.truncated_moments() };
    if args.draw.json {
        return print_json(&result);
    }
    outln!("{} grains, seed {} (std: population standard deviation)", args.draw.count, args.draw.seed)?;
    outln!("{:<4} {:>10} {:>10} {:>14} {:>14}", "", "mean", "std", "expected mean", "expected std")?;
    let e = &result.expected;
    for (name, m, s, em, es) in [
        ("FL", sampled.mean_fl, sampled.std_fl, e.mean_fl, e.std_fl),
        ("EL", sampled.mean_el, sampled.std_el, e.mean_el, e.std_el),
        ("EQ", sampled.mean_eq, sampled.std_eq, e.mean_eq, e.std_eq),
    ] {
        outln!("{name:<4} {m:>10.5} {s:>10.5} {em:>14.5} {es:>14.5}")?;
    }
    Ok(())
}

/// Running mean and population standard deviation (Welford).
#[derive(Default)]
struct Moments {
    n: f64,
    mean: f64,
    m2: f64,
}

impl Moments {
    fn add(&mut self, x: f64) {
        self.n += 1.0;
        let delta = x - self.mean;
        self.mean += delta / self.n;
        self.m2 += delta * (x - self.mean);
    }

    fn mean(&self) -> f64 {
        self.mean
    }

    fn std(&self) -> f64 {
        (self.m2 / self.n).sqrt()
    }
}

/// A sieve curve as written in files: sieve edges in metres and one mass fraction per class.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SieveCurveFile {
    pub sieves: Vec<f64>,
    pub fractions: Vec<f64>,
}

pub fn read_sieve_curve(path: &Path) -> anyhow::Result<SieveCurve> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    let file: SieveCurveFile = serde_norway::from_str(&text).with_context(|| format!("{}", path.display()))?;
    SieveCurve::new(file.sieves, file.fractions).with_context(|| format!("{}", path.display()))
}

#[derive(Serialize)]
struct SampledSizes {
    curve: String,
    count: u64,
    seed: u64,
    sieves: Vec<f64>,
    prescribed: Vec<f64>,
    /// Mass fraction per sieve class of the drawn grains (mass ∝ D³).
    mass_fractions: Vec<f64>,
    grains: Vec<u64>,
}

pub fn sizes(args: &SampleSizesArgs) -> anyhow::Result<()> {
    let (curve, name) = match (&args.case, &args.sieves) {
        (Some(case), _) => (SieveCurve::preset(case).context("--case")?, case.to_uppercase()),
        (None, Some(path)) => (read_sieve_curve(path)?, path.display().to_string()),
        (None, None) => unreachable!("clap requires --case or --sieves"),
    };
    let sampler = curve.sampler();
    let mut rng = ChaCha8Rng::seed_from_u64(args.draw.seed);
    let mut mass = vec![0.0; curve.classes()];
    let mut grains = vec![0u64; curve.classes()];
    for _ in 0..args.draw.count {
        let (class, d) = sampler.sample(&mut rng);
        mass[class] += d.powi(3);
        grains[class] += 1;
    }
    let total: f64 = mass.iter().sum();
    let result = SampledSizes {
        curve: name,
        count: args.draw.count,
        seed: args.draw.seed,
        sieves: curve.sieves().to_vec(),
        prescribed: curve.fractions().to_vec(),
        mass_fractions: mass.iter().map(|m| m / total).collect(),
        grains,
    };
    if args.draw.json {
        return print_json(&result);
    }
    outln!("{}: {} grains, seed {}", result.curve, result.count, result.seed)?;
    outln!("{:>18} {:>11} {:>9} {:>9}", "class (mm)", "prescribed", "sampled", "grains")?;
    for i in 0..curve.classes() {
        let class = format!("{:.2}–{:.2}", result.sieves[i] * 1e3, result.sieves[i + 1] * 1e3);
        outln!("{class:>18} {:>11.4} {:>9.4} {:>9}", result.prescribed[i], result.mass_fractions[i], result.grains[i])?;
    }
    let mut table = Table::default();
    table.row("largest sieve (m)", number(curve.largest_sieve()));
    table.print()?;
    Ok(())
}
