//! Everything about a single grain and a population of grains: form parameters and factors
//! (§2, Table 1), meshes, their simplification (§5.2.1) and their mass-equivalent ellipsoid
//! (Appendix A), sizes from sieve curves (§3.2, Table 3), form distributions (§7.1, §7.3),
//! generated pebble meshes and the bonded-sphere grains of the second paper (its §2.4 and
//! Appendix).

pub mod angularity;
pub mod bonded;
pub mod ellipsoid;
pub mod form;
pub mod form_distribution;
pub mod library;
pub mod mesh;
pub mod pebble;
pub mod simplify;
pub mod size;
pub mod unit_mesh;

pub use angularity::Angularity;
pub use bonded::{
    BondedGrain, ComponentSphere, EQUANT_EPSILON, SolidMass, ZinggClass, bonded_grain, construction, ellipsoid_mass,
    sphere_mass_properties,
};
pub use ellipsoid::EquivalentEllipsoid;
pub use form::{
    FactorValue, FormError, FormFactor, FormFactors, FormParameters, FormStatistic, Undefined, feature_names,
    form_statistics,
};
pub use form_distribution::{DistributionError, FormDistribution, FormMoments, FormSampler, RHINE_FORMS};
pub use library::{MeshLibrary, folder_meshes, rhine_meshes};
pub use mesh::{MassProperties, MeshDefect, MeshError, TriMesh};
pub use simplify::{Simplified, SimplifyError, simplify};
pub use size::{
    DrawnClass, SieveCurve, SizeError, SizeSampler, TABLE3, TABLE3_SIEVES, Table3Case, graded, mass_shares, trimmed,
};
pub use unit_mesh::UnitMesh;
