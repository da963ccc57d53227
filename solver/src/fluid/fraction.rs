//! The fluid fraction ε_f on a coarse grid, as unresolved CFD–DEM codes average it (Sun & Xiao
//! §2.1, "obtained by averaging the information of Lagrangian particles"): cubic cells a few
//! grain sizes wide, each grain's volume spread over the 8 cells around it with trilinear
//! (cloud-in-cell) weights and read back at any point with the same weights. The weights vary
//! continuously with position, so the fraction a grain sees, and its drag, do not jump as it
//! crosses a cell face.
//!
//! A grain is hindered by the others, not by itself (V_r of Eq. 6 is the settling velocity of a
//! grain among others over that of the grain alone), so the fraction a grain sees leaves out
//! its own deposit: a single grain in still water sees ε_f = 1 and settles as one grain alone.

use nalgebra::Vector3;

use crate::dem::Domain;

/// The smallest fluid fraction a grain is taken to see: the densest packing of equal spheres
/// leaves 0.26, so no bed of convex grains averages below it; only the trilinear spreading at a
/// cylinder wall could, and V_r (Eq. 6) vanishes at ε_f = 0.
pub const MIN_FLUID_FRACTION: f64 = 0.25;

/// Sample points per column side when measuring how much of a column lies inside a cylinder.
const WALL_SAMPLES: usize = 16;

/// Trilinear weights of one point: per axis two cell indices (equal where the point lies
/// within half a cell of a non-periodic boundary) and their weights.
#[derive(Debug, Clone, Copy, Default)]
pub struct Stencil {
    index: [[usize; 2]; 3],
    weight: [[f64; 2]; 3],
}

impl Stencil {
    /// Σ over cells of the product of the two points' weights: how much of a volume spread
    /// from one point is read back at the other.
    pub fn overlap(&self, other: &Stencil) -> f64 {
        let mut product = 1.0;
        for axis in 0..3 {
            let mut sum = 0.0;
            for p in 0..2 {
                for q in 0..2 {
                    if self.index[axis][p] == other.index[axis][q] {
                        sum += self.weight[axis][p] * other.weight[axis][q];
                    }
                }
            }
            product *= sum;
        }
        product
    }
}

/// Solid volume per cell of a grid over the domain: periodic in x and y for the periodic square,
/// bounded for the cylinder; from the floor up to the highest grain.
#[derive(Debug, Clone, Default)]
pub struct FractionGrid {
    cell: f64,
    counts: [usize; 3],
    periodic: bool,
    solid: Vec<f64>,
    /// Volume of each column's cells inside the domain (all of h³ in the periodic square).
    column_volume: Vec<f64>,
}

impl FractionGrid {
    /// Empties the grid for cells of about `cell` over `domain`, up to height `top`. The
    /// horizontal cell size divides the domain width exactly; cells are cubes.
    pub fn reset(&mut self, domain: &Domain, cell: f64, top: f64) {
        let width = domain.width();
        let across = ((width / cell).floor() as usize).max(1);
        let h = width / across as f64;
        let up = ((top.max(0.0) / h).ceil() as usize).max(1) + 1;
        let periodic = domain.is_periodic();
        if (h, across, periodic) != (self.cell, self.counts[0], self.periodic) {
            self.cell = h;
            self.periodic = periodic;
            self.column_volume = match domain {
                Domain::Periodic { .. } => vec![h * h * h; across * across],
                Domain::Cylinder { diameter } => {
                    let r2 = diameter * diameter / 4.0;
                    let inside = |i: usize, j: usize| {
                        let step = h / WALL_SAMPLES as f64;
                        let mut hits = 0;
                        for a in 0..WALL_SAMPLES {
                            for b in 0..WALL_SAMPLES {
                                let x = (i as f64) * h + (a as f64 + 0.5) * step - diameter / 2.0;
                                let y = (j as f64) * h + (b as f64 + 0.5) * step - diameter / 2.0;
                                hits += usize::from(x * x + y * y < r2);
                            }
                        }
                        hits as f64 / (WALL_SAMPLES * WALL_SAMPLES) as f64
                    };
                    (0..across * across).map(|c| h * h * h * inside(c % across, c / across)).collect()
                }
            };
        }
        self.counts = [across, across, up];
        self.solid.clear();
        self.solid.resize(across * across * up, 0.0);
    }

    /// Cell size h (m).
    pub fn cell(&self) -> f64 {
        self.cell
    }

    /// The trilinear weights of a point, cells centred at ((i + ½) h, (j + ½) h, (k + ½) h).
    #[inline]
    pub fn stencil(&self, x: &Vector3<f64>) -> Stencil {
        let mut stencil = Stencil::default();
        for axis in 0..3 {
            let n = self.counts[axis];
            let s = x[axis] / self.cell - 0.5;
            let below = s.floor();
            let t = s - below;
            let below = below as i64;
            let wrap = axis < 2 && self.periodic;
            let place = |i: i64| if wrap { i.rem_euclid(n as i64) as usize } else { i.clamp(0, n as i64 - 1) as usize };
            stencil.index[axis] = [place(below), place(below + 1)];
            stencil.weight[axis] = [1.0 - t, t];
        }
        stencil
    }

    fn cells(&self, stencil: &Stencil) -> impl Iterator<Item = (usize, usize, f64)> + '_ {
        let [nx, ny, _] = self.counts;
        let s = *stencil;
        (0..8).map(move |corner| {
            let (a, b, c) = (corner & 1, (corner >> 1) & 1, corner >> 2);
            let column = s.index[0][a] + nx * s.index[1][b];
            (column + nx * ny * s.index[2][c], column, s.weight[0][a] * s.weight[1][b] * s.weight[2][c])
        })
    }

    /// Spreads `volume` from the point of `stencil` over its 8 cells.
    #[inline]
    pub fn deposit(&mut self, stencil: &Stencil, volume: f64) {
        let [nx, ny, _] = self.counts;
        for corner in 0..8 {
            let (a, b, c) = (corner & 1, (corner >> 1) & 1, corner >> 2);
            let cell = stencil.index[0][a] + nx * (stencil.index[1][b] + ny * stencil.index[2][c]);
            self.solid[cell] += volume * stencil.weight[0][a] * stencil.weight[1][b] * stencil.weight[2][c];
        }
    }

    /// ε_f at the point of `stencil`, leaving out `own` (the solid volume the point's own grain
    /// spread that reads back there, Σ V_k overlap(k, point)): one minus the trilinear average of
    /// the solid over that of the domain's volume, at least [`MIN_FLUID_FRACTION`].
    #[inline]
    pub fn fluid_fraction(&self, stencil: &Stencil, own: f64) -> f64 {
        let (mut solid, mut room) = (-own, 0.0);
        for (cell, column, weight) in self.cells(stencil) {
            solid += weight * self.solid[cell];
            room += weight * self.column_volume[column];
        }
        (1.0 - solid.max(0.0) / room).clamp(MIN_FLUID_FRACTION, 1.0)
    }

    /// Total solid volume in the grid (for the conservation check).
    pub fn total(&self) -> f64 {
        self.solid.iter().sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(domain: Domain) -> FractionGrid {
        let mut g = FractionGrid::default();
        g.reset(&domain, 0.01, 0.05);
        g
    }

    #[test]
    fn spreading_keeps_every_volume_and_a_lone_grain_sees_clear_water() {
        let mut g = grid(Domain::Periodic { width: 0.1 });
        let points =
            [Vector3::new(0.0012, 0.0993, 0.0001), Vector3::new(0.05, 0.05, 0.049), Vector3::new(-0.01, 0.2, 0.02)];
        for (k, p) in points.iter().enumerate() {
            g.deposit(&g.stencil(p), 1e-6 * (k + 1) as f64);
        }
        assert!((g.total() - 6e-6).abs() < 1e-18, "{}", g.total());
        // One grain alone: its own deposit removed, the water is clear around it.
        let mut alone = grid(Domain::Periodic { width: 0.1 });
        let s = alone.stencil(&points[1]);
        alone.deposit(&s, 2e-7);
        assert_eq!(alone.fluid_fraction(&s, 2e-7 * s.overlap(&s)), 1.0);
    }

    #[test]
    fn a_uniform_suspension_reads_back_its_solid_fraction_everywhere() {
        // One grain of volume φ h³ at every cell centre (all the grid's cells up to 5 cm): the
        // fraction anywhere inside, own grain included, is φ; near the floor and wrapped across
        // the periodic faces too.
        let domain = Domain::Periodic { width: 0.1 };
        let mut g = grid(domain);
        let (h, phi) = (g.cell(), 0.3);
        for i in 0..10 {
            for j in 0..10 {
                for k in 0..6 {
                    let x = Vector3::new((i as f64 + 0.5) * h, (j as f64 + 0.5) * h, (k as f64 + 0.5) * h);
                    g.deposit(&g.stencil(&x), phi * h * h * h);
                }
            }
        }
        for p in
            [Vector3::new(0.0371, 0.0012, 0.0003), Vector3::new(0.0999, 0.05, 0.027), Vector3::new(0.013, 0.066, 0.041)]
        {
            let eps = g.fluid_fraction(&g.stencil(&p), 0.0);
            assert!((eps - (1.0 - phi)).abs() < 1e-12, "{p:?}: {eps}");
        }
    }

    #[test]
    fn the_cylinder_counts_only_the_water_inside_its_wall() {
        // A cylinder of diameter 0.1 filled uniformly: the fraction read near the wall is that of
        // the inside, although the wall cuts the cells (the domain's share of each column is
        // averaged with the same weights as the solid).
        let domain = Domain::Cylinder { diameter: 0.1 };
        let mut g = grid(domain);
        let phi = 0.2;
        let step = 0.002;
        let volume = phi * step * step * step;
        let mut z = step / 2.0;
        while z < 0.05 {
            let mut x = step / 2.0;
            while x < 0.1 {
                let mut y = step / 2.0;
                while y < 0.1 {
                    if (x - 0.05f64).powi(2) + (y - 0.05f64).powi(2) < 0.0025 {
                        g.deposit(&g.stencil(&Vector3::new(x, y, z)), volume);
                    }
                    y += step;
                }
                x += step;
            }
            z += step;
        }
        for p in [Vector3::new(0.05, 0.05, 0.02), Vector3::new(0.05, 0.003, 0.02), Vector3::new(0.016, 0.016, 0.03)] {
            let eps = g.fluid_fraction(&g.stencil(&p), 0.0);
            // Sampling the wall with 16 × 16 points per column and the grains on a 2 mm lattice
            // leaves a few per cent of φ.
            assert!((eps - (1.0 - phi)).abs() < 0.02, "{p:?}: {eps}");
        }
    }
}
