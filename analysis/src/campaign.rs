//! The analysis of a campaign, computed once: the feature table, the correlations of the form
//! factors (Fig. 3) and the model selection (§6.3, §7.2). The report only formats it.

use crate::correlation::{CorrelationMatrix, correlation_matrix};
use crate::dataset::{Dataset, DatasetError, FeatureKind};
use crate::form_factors::factors;
use crate::record::JobRecord;
use crate::selection::{Candidate, Selection, SelectionError, SelectionOptions, select_models};

/// Packings per fitted feature below which the report warns about the chosen model: with fewer,
/// each fold's fit has barely more rows than parameters and its cross-validated error says
/// little (the paper fitted four features to 52 packings, 13 each).
pub const PACKINGS_PER_FEATURE: usize = 5;

#[derive(Debug, Clone, PartialEq)]
pub struct Analysis {
    pub options: SelectionOptions,
    /// The feature table; None when no job has finished.
    pub dataset: Option<Dataset>,
    /// Pairwise r of the 13 form factors (single form) or of their means (mixtures), Fig. 3.
    pub factor_correlation: Option<CorrelationMatrix>,
    /// The models, or why none could be built; None without a dataset.
    pub selection: Option<Result<Selection, SelectionError>>,
}

/// How far the packings support the chosen model, for a caution beside the choice.
#[derive(Debug, Clone, PartialEq)]
pub struct Support<'a> {
    pub packings: usize,
    pub features: usize,
    /// Fewer than [`PACKINGS_PER_FEATURE`] packings per feature.
    pub few: bool,
    /// The fitted set with the smallest cross-validated MAE, when it is not the chosen one.
    pub better: Option<&'a Candidate>,
    /// The chosen set cross-validates worst of the fitted sets (and there are others).
    pub worst: bool,
}

impl Analysis {
    /// How the chosen model stands, if one was chosen.
    pub fn support(&self) -> Option<Support<'_>> {
        let (Some(dataset), Some(Ok(selection))) = (&self.dataset, &self.selection) else { return None };
        let chosen = &selection.sets[selection.chosen?];
        let mae = chosen.mae()?;
        let fitted: Vec<(&Candidate, f64)> = selection.sets.iter().filter_map(|c| Some((c, c.mae()?))).collect();
        let best = fitted.iter().min_by(|a, b| a.1.total_cmp(&b.1)).map(|&(c, m)| (c, m));
        let features = chosen.features.len();
        Some(Support {
            packings: dataset.len(),
            features,
            few: dataset.len() < PACKINGS_PER_FEATURE * features,
            better: best.filter(|&(_, m)| m < mae).map(|(c, _)| c),
            worst: fitted.len() > 1 && fitted.iter().all(|&(_, m)| m <= mae),
        })
    }
}

/// Builds the feature table of the finished jobs, correlates the form factors and runs the
/// model selection. Only a table that cannot be built (e.g. a job without its form statistics)
/// is an error; too few packings for models is part of the analysis.
pub fn analyse(records: &[JobRecord], campaign: &str, options: &SelectionOptions) -> Result<Analysis, DatasetError> {
    let dataset = match Dataset::from_records(records) {
        Ok(d) => Some(d),
        Err(DatasetError::NoRecords) => None,
        Err(e) => return Err(e),
    };
    let factor_correlation = dataset.as_ref().map(|d| {
        let names: Vec<String> = match d.kind() {
            FeatureKind::SingleForm => factors().iter().map(|f| f.to_string()).collect(),
            FeatureKind::Mixture => factors().iter().map(|f| format!("mean_{f}")).collect(),
        };
        correlation_matrix(d, &names)
    });
    let selection = dataset.as_ref().map(|d| select_models(d, campaign, options));
    Ok(Analysis { options: *options, dataset, factor_correlation, selection })
}
