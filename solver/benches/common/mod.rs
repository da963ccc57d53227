//! Random inputs shared by the contact benchmarks.

use nalgebra::Vector3;
use rand::RngExt;
use rand_chacha::ChaCha8Rng;

/// A direction drawn uniformly on the unit sphere (rejection from the cube).
pub fn random_unit(rng: &mut ChaCha8Rng) -> Vector3<f64> {
    loop {
        let v = Vector3::from_fn(|_, _| rng.random_range(-1.0..1.0));
        if (0.01..1.0).contains(&v.norm()) {
            return v.normalize();
        }
    }
}
