//! Porosity evaluation of §4.4, by the rule of the paper's own software: every grain becomes a
//! sphere of equal volume at its centre of mass, whose exact spherical-segment volumes are
//! accumulated in horizontal slices; the free surface is the slice where the solid fraction
//! crosses 1 − n_cut-off scanning from the top; the bulk porosity averages the whole slices
//! between the trims (Eq. 16).

use serde::{Deserialize, Serialize};
use thiserror::Error;

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PorositySettings {
    /// Slice height h_p (m), 1 mm in the paper.
    pub slice: f64,
    /// Porosity at the free surface, n_cut-off = 0.5.
    pub cutoff: f64,
    /// Height cut away above the floor and below the free surface (m): h_pd for the periodic
    /// domain (the largest sieve size, §6.1), 0 for the cylinder.
    pub trim: f64,
}

#[derive(Debug, Error, Clone, PartialEq)]
pub enum PorosityError {
    #[error("no grains to evaluate")]
    Empty,
    #[error("no packing surface found: the solid fraction never rises above {0} from the top down")]
    NoSurface(f64),
    #[error("the packing (surface at {surface} m) is too thin for the trim of {trim} m at both ends")]
    TooThin { surface: f64, trim: f64 },
    #[error("slices of {slice:e} m cut a packing {height} m high into more than {MAX_SLICES} slices")]
    TooManySlices { slice: f64, height: f64 },
}

/// More slices than this mean a slice thickness mistaken for another unit, not a wish.
pub const MAX_SLICES: f64 = 1e7;

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ProfilePoint {
    /// Slice centre (m).
    pub z: f64,
    /// Porosity of the slice.
    pub n: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Porosity {
    /// Bulk porosity ⟨n⟩ of Eq. 16 over [z_minus, z_plus].
    pub bulk: f64,
    /// Bottom of the first and top of the last slice averaged (m).
    pub z_minus: f64,
    pub z_plus: f64,
    /// The free surface z₊ᶜᵈ = K·h (m).
    pub surface: f64,
    pub profile: Vec<ProfilePoint>,
}

/// Volume of the part of a sphere (centre height `z`, radius `r`) between heights a < b.
fn segment_volume(z: f64, r: f64, a: f64, b: f64) -> f64 {
    let (lo, hi) = ((a - z).max(-r), (b - z).min(r));
    if hi <= lo {
        return 0.0;
    }
    std::f64::consts::PI * (r * r * (hi - lo) - (hi.powi(3) - lo.powi(3)) / 3.0)
}

/// Solid fraction of each slice k, [k h, (k + 1) h], of spheres given as (centre height,
/// radius) in a domain of horizontal cross-section `area`, up to one slice more than the
/// spheres reach (so that the top slice is empty); slice 0 also takes what lies below the floor.
pub fn solid_fractions(spheres: &[(f64, f64)], area: f64, h: f64) -> Vec<f64> {
    let top = spheres.iter().map(|(z, r)| z + r).fold(f64::NEG_INFINITY, f64::max);
    let count = (top / h).ceil().max(0.0) as usize + 1;
    let mut solid = vec![0.0; count];
    for &(z, r) in spheres {
        let first = ((z - r) / h).floor().max(0.0) as usize;
        let last = (((z + r) / h).floor().max(0.0) as usize).min(count - 1);
        for (k, volume) in solid.iter_mut().enumerate().take(last + 1).skip(first) {
            let a = if k == 0 { f64::NEG_INFINITY } else { k as f64 * h };
            *volume += segment_volume(z, r, a, (k + 1) as f64 * h);
        }
    }
    solid.iter().map(|v| v / (area * h)).collect()
}

/// The free-surface index K of §4.4: scanning from the top down, the first k ≥ 1 with
/// φ_k ≤ `threshold` ≤ φ_{k−1}; None when the fraction never crosses it.
pub fn surface_index(fraction: &[f64], threshold: f64) -> Option<usize> {
    (1..fraction.len()).rev().find(|&k| fraction[k] <= threshold && threshold <= fraction[k - 1])
}

/// Evaluates the porosity of volume-equivalent spheres given as (centre height, radius) in a
/// domain of horizontal cross-section `area` (m²). Horizontal positions do not matter: in a
/// periodic domain every grain counts whole wherever it lies.
pub fn evaluate(spheres: &[(f64, f64)], area: f64, settings: &PorositySettings) -> Result<Porosity, PorosityError> {
    if spheres.is_empty() {
        return Err(PorosityError::Empty);
    }
    let h = settings.slice;
    let top = spheres.iter().map(|(z, r)| z + r).fold(f64::NEG_INFINITY, f64::max);
    if top / h > MAX_SLICES {
        return Err(PorosityError::TooManySlices { slice: h, height: top });
    }
    let fraction = solid_fractions(spheres, area, h);
    let threshold = 1.0 - settings.cutoff;
    let surface_index = surface_index(&fraction, threshold).ok_or(PorosityError::NoSurface(threshold))?;
    let surface = surface_index as f64 * h;

    // Whole slices inside [T, K h − T]; the tolerance absorbs round-off in k·h.
    let eps = 1e-9 * h;
    let inside: Vec<usize> = (0..surface_index)
        .filter(|&k| k as f64 * h >= settings.trim - eps && (k + 1) as f64 * h <= surface - settings.trim + eps)
        .collect();
    let (Some(&first), Some(&last)) = (inside.first(), inside.last()) else {
        return Err(PorosityError::TooThin { surface, trim: settings.trim });
    };
    let bulk = inside.iter().map(|&k| 1.0 - fraction[k]).sum::<f64>() / inside.len() as f64;
    Ok(Porosity {
        bulk,
        z_minus: first as f64 * h,
        z_plus: (last + 1) as f64 * h,
        surface,
        profile: fraction
            .iter()
            .enumerate()
            .map(|(k, f)| ProfilePoint { z: (k as f64 + 0.5) * h, n: 1.0 - f })
            .collect(),
    })
}
