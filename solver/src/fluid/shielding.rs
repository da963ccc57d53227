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
//! - a sphere j downstream sees its slip reduced by that deficit times the share of its own
//!   cross-section inside the wake disk; deficits of several upstream spheres compound.
//!
//! Side by side across the flow no cross-section overlaps a wake, so a disk broadside-on is
//! unsheltered, and edge-on its trailing spheres are sheltered: the drag concentrates at the
//! leading edge and turns the grain broadside-on.

use std::f64::consts::PI;

use nalgebra::Vector3;

use super::drag::{DallaValle, DragCurve};

/// One component sphere of a grain as the fluid sees it.
#[derive(Debug, Clone, Copy)]
pub struct WetSphere {
    pub center: Vector3<f64>,
    pub radius: f64,
    /// Fluid velocity minus the sphere's velocity at its centre.
    pub slip: Vector3<f64>,
}

/// Area of the intersection of two disks of radii `a` and `b` whose centres are `d` apart.
pub fn lens_area(a: f64, b: f64, d: f64) -> f64 {
    if d >= a + b {
        return 0.0;
    }
    let small = a.min(b);
    if d <= (a - b).abs() {
        return PI * small * small;
    }
    let alpha = ((d * d + a * a - b * b) / (2.0 * d * a)).clamp(-1.0, 1.0).acos();
    let beta = ((d * d + b * b - a * a) / (2.0 * d * b)).clamp(-1.0, 1.0).acos();
    a * a * (alpha - alpha.sin() * alpha.cos()) + b * b * (beta - beta.sin() * beta.cos())
}

/// Reduces each sphere's slip by the wakes of the grain's spheres upstream of it (module doc).
/// The flow direction and speed are those of the grain's volume-weighted mean slip, taken
/// before any sphere is sheltered.
pub fn shelter(spheres: &mut [WetSphere], kinematic_viscosity: f64) {
    if spheres.len() < 2 {
        return;
    }
    let mean: Vector3<f64> = spheres.iter().map(|s| s.slip * s.radius.powi(3)).sum();
    let speed = mean.norm() / spheres.iter().map(|s| s.radius.powi(3)).sum::<f64>();
    if speed == 0.0 {
        return;
    }
    let along = mean.normalize();
    for j in 0..spheres.len() {
        let (center, radius) = (spheres[j].center, spheres[j].radius);
        let factor: f64 = spheres
            .iter()
            .filter_map(|i| {
                let offset = center - i.center;
                let x = offset.dot(&along);
                if x <= 0.0 {
                    return None;
                }
                let lateral = (offset - x * along).norm();
                let wake2 = i.radius * i.radius + 4.0 * kinematic_viscosity * x / speed;
                let reynolds = 2.0 * i.radius * speed / kinematic_viscosity;
                let deficit = (0.5 * DallaValle.drag_coefficient(reynolds) * i.radius * i.radius / wake2).min(1.0);
                let covered = lens_area(radius, wake2.sqrt(), lateral) / (PI * radius * radius);
                let behind = 1.0 - (-speed * x / kinematic_viscosity).exp();
                Some(1.0 - deficit * covered * behind)
            })
            .product();
        spheres[j].slip *= factor;
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

    fn pair(offset: Vector3<f64>, speed: f64) -> [WetSphere; 2] {
        let slip = Vector3::new(0.0, 0.0, speed);
        [WetSphere { center: Vector3::zeros(), radius: 1e-3, slip }, WetSphere { center: offset, radius: 1e-3, slip }]
    }

    #[test]
    fn only_the_trailing_sphere_of_a_line_along_the_flow_is_sheltered() {
        // Water rising past the grain at 0.1 m/s (a grain sinking in still water); d = 2 mm,
        // Re = 200, C_D = (0.63 + 4.8/√200)² = 0.9395; touching, x = d: R² = r² + 4ν d/|w| = 1.08 r²
        // and the wake weight is 1 − e^(−200) = 1, so the upper sphere keeps 1 − (0.9395/2)/1.08
        // of its slip.
        let mut line = pair(Vector3::new(0.0, 0.0, 2e-3), 0.1);
        shelter(&mut line, 1e-6);
        let cd = (0.63 + 4.8 / 200f64.sqrt()).powi(2);
        assert_eq!(line[0].slip.z, 0.1);
        assert!((line[1].slip.z / 0.1 - (1.0 - cd / 2.0 / 1.08)).abs() < 1e-12, "{}", line[1].slip.z);
        // Side by side across the flow: nobody is in anybody's wake.
        let mut across = pair(Vector3::new(2e-3, 0.0, 0.0), 0.1);
        shelter(&mut across, 1e-6);
        assert_eq!((across[0].slip.z, across[1].slip.z), (0.1, 0.1));
    }

    #[test]
    fn the_shelter_fades_in_creeping_flow() {
        // |w| x/ν = 0.002 (Re = 0.002): the wake weight 1 − e^(−0.002) leaves 0.2 % of a deficit.
        let mut slow = pair(Vector3::new(0.0, 0.0, 2e-3), 1e-6);
        shelter(&mut slow, 1e-6);
        assert!(1.0 - slow[1].slip.z / 1e-6 < 0.002 + 1e-12, "{}", slow[1].slip.z);
    }
}
