//! Porosity models from packing results (§6.3, §7.2 of Rettinger et al. 2022). The analysis
//! reads plain job records and feature tables by column name; it knows nothing of the DEM or of
//! SQLite. Data flow: `[JobRecord]` → `analyse` (the `Dataset`, the factor correlations and the
//! `Selection`: ranking, filter, pair and set fits with k-fold CV) → `Analysis` → report files,
//! which only format it; saved models are applied by `prediction`.

pub mod campaign;
pub mod correlation;
pub mod cross_validation;
pub mod csv;
pub mod dataset;
pub mod form_factors;
pub mod model;
pub mod paper;
pub mod plots;
pub mod prediction;
pub mod record;
pub mod regression;
pub mod report;
pub mod selection;

pub use campaign::{Analysis, PACKINGS_PER_FEATURE, Support, analyse};
pub use correlation::{CorrelationMatrix, FeatureCorrelation, Ranking, correlation_matrix, pearson, rank_features};
pub use cross_validation::{CvError, CvOutcome, assign_folds, cross_validate};
pub use dataset::{Dataset, DatasetError, DroppedFeature, FeatureKind};
pub use model::{CrossValidation, LinearModel, ModelError};
pub use prediction::{FormStatistics, ModelInput, Prediction, PredictionError, load_model, predict};
pub use record::{CampaignSummary, Experiment, JobRecord};
pub use regression::{Fit, FitError, fit_least_squares};
pub use report::{ReportError, ReportFiles, write_report};
pub use selection::{Candidate, FittedModel, Selection, SelectionError, SelectionOptions, select_models};
