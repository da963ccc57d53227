//! Pearson correlation of features with porosity and with each other (§2.3, §6.3.2, §7.2).

use serde::Serialize;

use crate::dataset::Dataset;

/// |r| values closer than this count as a tie when picking the primary feature; the earlier
/// column (Table 1 order, plain before inverse) wins, so the choice does not hang on rounding.
pub const TIE_TOLERANCE: f64 = 1e-12;

/// Pearson's r, or None when fewer than two points or either variable is constant. One pass
/// with Welford's co-moment update, which stays accurate when the means are large.
pub fn pearson(x: &[f64], y: &[f64]) -> Option<f64> {
    assert_eq!(x.len(), y.len(), "pearson needs paired samples");
    if x.len() < 2 {
        return None;
    }
    let (mut mean_x, mut mean_y, mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (k, (&a, &b)) in x.iter().zip(y).enumerate() {
        let n = (k + 1) as f64;
        let dx = a - mean_x;
        let dy = b - mean_y;
        mean_x += dx / n;
        mean_y += dy / n;
        sxx += dx * (a - mean_x);
        syy += dy * (b - mean_y);
        sxy += dx * (b - mean_y);
    }
    // A column whose spread is rounding noise relative to its values is constant.
    let scale_x = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let scale_y = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let n = x.len() as f64;
    let negligible = |s: f64, scale: f64| s <= (1e-12 * scale).powi(2) * n;
    if negligible(sxx, scale_x) || negligible(syy, scale_y) {
        return None;
    }
    Some((sxy / (sxx * syy).sqrt()).clamp(-1.0, 1.0))
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FeatureCorrelation {
    pub feature: String,
    pub r: f64,
}

/// Features by |r| with porosity, largest first; constant features cannot be ranked.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Ranking {
    pub ranked: Vec<FeatureCorrelation>,
    pub constant: Vec<String>,
}

impl Ranking {
    /// The feature most correlated with porosity; ties within `TIE_TOLERANCE` go to the earlier
    /// dataset column.
    pub fn primary(&self, dataset: &Dataset) -> Option<&FeatureCorrelation> {
        let best = self.ranked.first()?.r.abs();
        let position = |f: &str| dataset.features().iter().position(|c| c == f).unwrap_or(usize::MAX);
        self.ranked.iter().take_while(|c| c.r.abs() >= best - TIE_TOLERANCE).min_by_key(|c| position(&c.feature))
    }
}

/// Pearson r of every feature with porosity, ranked by |r| (stable: equal |r| keep column order).
pub fn rank_features(dataset: &Dataset) -> Ranking {
    let mut ranked = Vec::new();
    let mut constant = Vec::new();
    for f in dataset.features() {
        let column = dataset.column(f).expect("listed feature has a column");
        match pearson(column, dataset.porosity()) {
            Some(r) => ranked.push(FeatureCorrelation { feature: f.clone(), r }),
            None => constant.push(f.clone()),
        }
    }
    ranked.sort_by(|a, b| b.r.abs().total_cmp(&a.r.abs()));
    Ranking { ranked, constant }
}

/// Pairwise r of a set of features (Fig. 3); None where a feature is constant.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CorrelationMatrix {
    pub features: Vec<String>,
    pub r: Vec<Vec<Option<f64>>>,
}

/// The correlation matrix of the given features that the dataset has (others are skipped).
pub fn correlation_matrix(dataset: &Dataset, features: &[String]) -> CorrelationMatrix {
    let present: Vec<(&String, &[f64])> = features.iter().filter_map(|f| dataset.column(f).map(|c| (f, c))).collect();
    let r = present.iter().map(|(_, a)| present.iter().map(|(_, b)| pearson(a, b)).collect()).collect();
    CorrelationMatrix { features: present.into_iter().map(|(f, _)| f.clone()).collect(), r }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn perfect_and_undefined_correlations() {
        assert_eq!(pearson(&[1.0, 2.0, 3.0], &[2.0, 4.0, 6.0]), Some(1.0));
        assert_eq!(pearson(&[1.0, 2.0, 3.0], &[3.0, 2.0, 1.0]), Some(-1.0));
        assert_eq!(pearson(&[1.0, 1.0, 1.0], &[3.0, 2.0, 1.0]), None);
        assert_eq!(pearson(&[1.0], &[3.0]), None);
    }
}
