//! Shelter of a bonded grain's spheres in the wakes of the grain's other spheres.
//!
//! In the second paper the fluid is solved with the grains (two-way coupling) on cells about
//! one grain wide (its Table 1), so the water a sphere drags along slows the water reaching
//! the spheres behind it; that is how its bonded grains "adjust to an orientation where the
//! maximum projection is normal to the fall velocity" (§3, Fig. 7). A prescribed velocity field
//! has no such feedback: without it a bonded disk drags alike in every orientation and keeps the
//! one it was released with. This model puts the feedback back inside each grain, and is
//! sedpack's, not the paper's:
//!
//! - the wake of an upstream sphere i (radius r_i, drag coefficient C_D,i at the grain's slip
//!   speed |w|) is a disk across the flow whose radius grows by viscous diffusion,
//!   R² = r_i² + 4 ν x/|w| at a distance x downstream (the laminar wake: Landau & Lifshitz,
//!   *Fluid Mechanics*, §21; Batchelor 1967, §5.12);
//! - the velocity deficit in it carries the sphere's drag as a momentum deficit,
//!   ρ |w| u_d π R² = C_D,i ½ ρ |w|² π r_i², so u_d/|w| = (C_D,i/2) r_i²/R², at most 1 (the
//!   momentum argument of actuator-disk theory);
//! - only the part of the disturbance that inertia leaves behind is a wake: in Oseen's solution
//!   the disturbance a distance x upstream is e^(−|w| x/ν) of that downstream, so the deficit
//!   counts with the weight 1 − e^(−|w| x/ν), which vanishes in Stokes flow, where a rigid
//!   body's drag is fore-aft symmetric and a disk keeps whatever orientation it has;
//! - a sphere j sees its slip reduced by that deficit times the share of its own cross-section
//!   inside the wake disk, for each sphere of the grain it touches upstream (the nearest wakes:
//!   those of spheres farther up have passed through these, which are themselves slowed, so
//!   they are not counted again); the deficits of two or three touching spheres upstream
//!   compound.
//!
//! Side by side across the flow no cross-section overlaps a wake, so a disk broadside-on is
//! unsheltered, and edge-on its trailing spheres are sheltered: the drag concentrates at the
//! leading edge and turns the grain broadside-on.

use std::f64::consts::PI;

use nalgebra::Vector3;

use super::drag::{DallaValle, DragCurve};

/// Area of the intersection of two disks of radii `a` and `b` whose centres are `d` apart.
pub fn lens_area(a: f64, b: f64, d: f64) -> f64 {
    if d >= a + b {
        return 0.0;
    }
    let small = a.min(b);
    if d <= (a - b).abs() {
        return PI * small * small;
    }
    // Each disk contributes the segment cut off by the chord: r² (θ − sin θ cos θ) with cos θ
    // from the triangle of the two centres and a crossing point.
    let segment = |r: f64, c: f64| {
        let c = c.clamp(-1.0, 1.0);
        r * r * (c.acos() - c * (1.0 - c * c).sqrt())
    };
    segment(a, (d * d + a * a - b * b) / (2.0 * d * a)) + segment(b, (d * d + b * b - a * a) / (2.0 * d * b))
}

/// The flow past a grain: direction and speed of its volume-weighted mean slip.
#[derive(Debug, Clone, Copy)]
pub struct Wake {
    along: Vector3<f64>,
    speed: f64,
    kinematic_viscosity: f64,
}

impl Wake {
    /// The wakes of a grain whose spheres slip past the fluid at `mean_slip` on average; None
    /// for a grain at rest in the fluid.
    pub fn new(mean_slip: &Vector3<f64>, kinematic_viscosity: f64) -> Option<Self> {
        let speed = mean_slip.norm();
        (speed > 0.0).then(|| Self { along: mean_slip / speed, speed, kinematic_viscosity })
    }

    /// The share of its slip that a sphere (`center`, `radius`) keeps behind the spheres
    /// `touching` it (centre, radius): the product over those upstream of 1 − deficit × covered
    /// × behind. A wake weighted below 1e-3 (|w| x/ν < 1e-3, creeping flow) would change the
    /// slip by less than 0.1 % and is not evaluated.
    pub fn shelter(
        &self,
        center: &Vector3<f64>,
        radius: f64,
        touching: impl Iterator<Item = (Vector3<f64>, f64)>,
    ) -> f64 {
        let nu = self.kinematic_viscosity;
        let mut factor = 1.0;
        for (upstream, r) in touching {
            let offset = center - upstream;
            let x = offset.dot(&self.along);
            if self.speed * x < 1e-3 * nu {
                continue;
            }
            let lateral2 = (offset.norm_squared() - x * x).max(0.0);
            let wake2 = r * r + 4.0 * nu * x / self.speed;
            // Disks of radii r_j and R overlap only closer than r_j + R.
            if lateral2 >= radius * radius + wake2 + 2.0 * radius * wake2.sqrt() {
                continue;
            }
            let reynolds = 2.0 * r * self.speed / nu;
            let deficit = (0.5 * DallaValle.drag_coefficient(reynolds) * r * r / wake2).min(1.0);
            let covered = lens_area(radius, wake2.sqrt(), lateral2.sqrt()) / (PI * radius * radius);
            let behind = 1.0 - (-self.speed * x / nu).exp();
            factor *= 1.0 - deficit * covered * behind;
        }
        factor
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lens_area_runs_from_disjoint_to_contained() {
        assert_eq!(lens_area(1.0, 1.0, 2.0), 0.0);
        assert!((lens_area(1.0, 2.0, 0.5) - PI).abs() < 1e-12);
        // Two unit disks one radius apart: 2π/3 − √3/2.
        assert!((lens_area(1.0, 1.0, 1.0) - (2.0 * PI / 3.0 - 3f64.sqrt() / 2.0)).abs() < 1e-12);
    }

    /// The shelter factors of two touching 1 mm spheres, the second at `offset`, slipping
    /// together at `speed` up the z axis.
    fn pair(offset: Vector3<f64>, speed: f64) -> [f64; 2] {
        let wake = Wake::new(&Vector3::new(0.0, 0.0, speed), 1e-6).unwrap();
        let (a, b) = ((Vector3::zeros(), 1e-3), (offset, 1e-3));
        [wake.shelter(&a.0, a.1, [b].into_iter()), wake.shelter(&b.0, b.1, [a].into_iter())]
    }

    #[test]
    fn only_the_trailing_sphere_of_a_line_along_the_flow_is_sheltered() {
        // Water rising past the grain at 0.1 m/s (a grain sinking in still water); d = 2 mm,
        // Re = 200, C_D = (0.63 + 4.8/√200)² = 0.9395; touching, x = d: R² = r² + 4ν d/|w| = 1.08 r²
        // and the wake weight is 1 − e^(−200) = 1, so the upper sphere keeps 1 − (0.9395/2)/1.08
        // of its slip.
        let line = pair(Vector3::new(0.0, 0.0, 2e-3), 0.1);
        let cd = (0.63 + 4.8 / 200f64.sqrt()).powi(2);
        assert_eq!(line[0], 1.0);
        assert!((line[1] - (1.0 - cd / 2.0 / 1.08)).abs() < 1e-12, "{}", line[1]);
        // Side by side across the flow: nobody is in anybody's wake.
        assert_eq!(pair(Vector3::new(2e-3, 0.0, 0.0), 0.1), [1.0, 1.0]);
        assert_eq!(Wake::new(&Vector3::zeros(), 1e-6).map(|_| ()), None);
    }

    #[test]
    fn the_shelter_fades_in_creeping_flow() {
        // |w| x/ν = 0.004: the wake weight 1 − e^(−0.004) leaves at most 0.4 % of a deficit;
        // below 1e-3 none is counted.
        let slow = pair(Vector3::new(0.0, 0.0, 2e-3), 2e-6);
        assert!(1.0 - slow[1] < 0.004 && slow[1] < 1.0, "{}", slow[1]);
        assert_eq!(pair(Vector3::new(0.0, 0.0, 2e-3), 4e-7), [1.0, 1.0]);
    }
}
