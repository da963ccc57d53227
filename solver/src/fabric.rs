//! Imbrication: how the grains' long axes lie relative to a current. Gravel deposited by a
//! current leans against it: its long axes (or flat faces) dip upstream, shingled like roof
//! tiles; the distribution of the long axis' dip and of the direction it dips towards, against
//! the flow, is the fabric a sedimentologist measures in the field.

use nalgebra::{UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::dem::Shape;
use crate::fluid::settling::principal_axes;

/// Bins of the dip histogram: 10° wide over [0°, 90°].
pub const DIP_BINS: usize = 9;
/// Bins of the direction histogram: 30° wide over (−180°, 180°], centred on 0° (downstream),
/// ±30°, …, 180° (upstream).
pub const DIRECTION_BINS: usize = 12;

/// The long-axis fabric of a packing, against the flow direction +x.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Imbrication {
    /// Grains with a long axis (a sphere or a one-sphere grain has none).
    pub grains: usize,
    /// Share of the grains per dip class: angle between long axis and horizontal, [10 k, 10 k + 10)°.
    pub dip: Vec<f64>,
    /// Share of the grains per dip direction: the azimuth, from the flow direction, of the end of
    /// the long axis that points down; bin k is centred on 30 k° (k = 0 … 11, 180° = upstream).
    pub direction: Vec<f64>,
    /// Mean dip (°).
    pub mean_dip: f64,
    /// Share of the grains whose long axis dips upstream (direction more than 90° from the flow).
    pub upstream: f64,
    /// Mean resultant of the dip directions weighted by sin(dip) (a level axis has no dip
    /// direction): its azimuth (°, from the flow; ±180 upstream) and length (0: no preferred
    /// direction, 1: all alike).
    pub resultant_direction: f64,
    pub resultant_length: f64,
}

/// The fabric of bodies with these shapes and orientations, None when none has a long axis.
pub fn imbrication(shapes: &[Shape], orientations: &[UnitQuaternion<f64>]) -> Option<Imbrication> {
    let mut dip = vec![0.0; DIP_BINS];
    let mut direction = vec![0.0; DIRECTION_BINS];
    let (mut grains, mut dips, mut upstream) = (0usize, 0.0, 0usize);
    let (mut sum, mut weights) = (Vector3::zeros(), 0.0);
    for (shape, q) in shapes.iter().zip(orientations) {
        let (Some(long), _) = principal_axes(shape) else { continue };
        // The end of the long axis that points down.
        let mut a: Vector3<f64> = q * long;
        if a.z > 0.0 {
            a = -a;
        }
        let angle = (-a.z).min(1.0).asin().to_degrees();
        let azimuth = a.y.atan2(a.x).to_degrees();
        grains += 1;
        dips += angle;
        dip[((angle / 10.0) as usize).min(DIP_BINS - 1)] += 1.0;
        direction[(((azimuth + 375.0) / 30.0) as usize) % DIRECTION_BINS] += 1.0;
        upstream += usize::from(azimuth.abs() > 90.0);
        let weight = -a.z;
        let horizontal = Vector3::new(a.x, a.y, 0.0);
        if horizontal.norm() > 0.0 {
            sum += horizontal.normalize() * weight;
            weights += weight;
        }
    }
    if grains == 0 {
        return None;
    }
    let n = grains as f64;
    let share = |v: Vec<f64>| v.into_iter().map(|c| c / n).collect();
    Some(Imbrication {
        grains,
        dip: share(dip),
        direction: share(direction),
        mean_dip: dips / n,
        upstream: upstream as f64 / n,
        resultant_direction: sum.y.atan2(sum.x).to_degrees(),
        resultant_length: if weights > 0.0 { sum.norm() / weights } else { 0.0 },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rod() -> Shape {
        Shape::Ellipsoid { semi_axes: Vector3::new(2.0, 1.0, 0.8) }
    }

    #[test]
    fn grains_leaning_against_the_flow_dip_upstream() {
        // Long axis (body x) turned 25° about +y: its +x end rises, so the end pointing down is
        // −x, the upstream side: dip 25° (mid-class: 20° would sit on a class edge), direction 180°.
        let lean = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), -25f64.to_radians());
        let f = imbrication(&[rod(), rod()], &[lean, lean]).unwrap();
        assert_eq!(f.grains, 2);
        assert!((f.mean_dip - 25.0).abs() < 1e-9);
        assert_eq!(f.dip[2], 1.0);
        assert_eq!(f.direction[6], 1.0);
        assert_eq!(f.upstream, 1.0);
        assert!((f.resultant_direction.abs() - 180.0).abs() < 1e-9 && (f.resultant_length - 1.0).abs() < 1e-12);
        // Mirrored grains cancel in the resultant; a sphere has no long axis.
        let other = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), 25f64.to_radians());
        let both = imbrication(&[rod(), rod(), Shape::Sphere { radius: 1.0 }], &[lean, other, lean]).unwrap();
        assert_eq!((both.grains, both.upstream), (2, 0.5));
        assert!(both.resultant_length < 1e-12);
        assert_eq!(imbrication(&[Shape::Sphere { radius: 1.0 }], &[lean]), None);
    }
}
