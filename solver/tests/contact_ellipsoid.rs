//! The ellipsoid narrow phase against references built independently of it: depth and normal
//! within 1e-6, relative to the smallest semi-axis, of a high-precision reference; the same
//! point, depth and opposite normal for both bodies of a pair.
//!
//! The references evaluate the support function in the body frame, |diag(a, b, c) Rᵀ n|, never
//! through the library's Q, and find minima by a dense latitude–longitude grid, a compass search
//! and a Newton polish whose Jacobian is taken by finite differences.

use nalgebra::{Matrix2, Matrix3, UnitQuaternion, Vector2, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use solver::dem::contact::ContactGeometry;
use solver::dem::contact::ellipsoid::{
    EllipsoidPose, ellipsoid_cylinder_wall, ellipsoid_ellipsoid, ellipsoid_ellipsoid_with_stats, ellipsoid_plane,
};
use solver::dem::uniform_rotation;

type V3 = Vector3<f64>;

/// Accepted error of depth (relative to the smallest semi-axis) and normal.
const ACCEPTANCE: f64 = 1e-6;

#[derive(Debug, Clone, Copy)]
struct Body {
    x: V3,
    r: Matrix3<f64>,
    axes: V3,
}

impl Body {
    fn pose(&self) -> EllipsoidPose {
        EllipsoidPose::new(self.x, &self.r, self.axes)
    }

    fn smallest(&self) -> f64 {
        self.axes.min()
    }

    fn rolling_radius(&self) -> f64 {
        self.axes.min().powi(2) / self.axes.max()
    }

    fn largest_curvature_radius(&self) -> f64 {
        self.axes.max().powi(2) / self.axes.min()
    }

    fn h(&self, n: &V3) -> f64 {
        self.axes.component_mul(&(self.r.transpose() * n)).norm()
    }

    /// Support point relative to the centre, R diag(a²) Rᵀ n / h(n).
    fn reach(&self, n: &V3) -> V3 {
        let body = self.r.transpose() * n;
        self.r * self.axes.component_mul(&self.axes).component_mul(&body) / self.h(n)
    }

    /// |diag(a, b, c)⁻¹ Rᵀ (p − x)|: 1 exactly on the surface.
    fn level(&self, p: &V3) -> f64 {
        (self.r.transpose() * (p - self.x)).component_div(&self.axes).norm()
    }

    fn outward_normal(&self, p: &V3) -> V3 {
        let body = (self.r.transpose() * (p - self.x)).component_div(&self.axes.component_mul(&self.axes));
        (self.r * body).normalize()
    }
}

fn random_rotation(rng: &mut ChaCha8Rng) -> Matrix3<f64> {
    uniform_rotation(rng).to_rotation_matrix().into_inner()
}

/// Semi-axes of `scale` × [1, 10] each: aspect ratios up to 10:1.
fn random_axes(rng: &mut ChaCha8Rng, scale: f64) -> V3 {
    V3::from_fn(|_, _| scale * 10f64.powf(rng.random_range(0.0..1.0)))
}

/// The extremes of 10:1: needles (10, s, 1)·scale with s near 1, plates with s near 10, and
/// everything between, in a random body-axis order.
fn random_extreme_axes(rng: &mut ChaCha8Rng, scale: f64) -> V3 {
    let mut axes = V3::new(10.0, 10f64.powf(rng.random_range(0.0..1.0)), 1.0) * scale;
    axes.as_mut_slice().swap(0, rng.random_range(0..3));
    axes
}

fn random_unit(rng: &mut ChaCha8Rng) -> V3 {
    loop {
        let v = V3::from_fn(|_, _| rng.random_range(-1.0..1.0));
        if (0.01..1.0).contains(&v.norm()) {
            return v.normalize();
        }
    }
}

/// A at the origin and B at `fraction` of the reach of both along a random direction: small
/// fractions give deep overlaps, fractions near and above 1 shallow ones and separation.
fn random_pair(rng: &mut ChaCha8Rng, scale_b: f64, fraction: std::ops::Range<f64>) -> (Body, Body) {
    let a = Body { x: V3::zeros(), r: random_rotation(rng), axes: random_axes(rng, 1.0) };
    let mut b = Body { x: V3::zeros(), r: random_rotation(rng), axes: random_axes(rng, scale_b) };
    let m = random_unit(rng);
    b.x = m * (rng.random_range(fraction) * (a.h(&m) + b.h(&m)));
    (a, b)
}

/// B placed against A so that their support points along the unit `n` lie `depth` apart
/// (B's behind A's when depth > 0). Then n is a critical point of f with f(n) = depth, so when
/// depth < ρ_A + ρ_B it is the unique global minimum: depth, normal and point are known exactly.
fn placed_against(a: &Body, b: &Body, n: &V3, depth: f64) -> Body {
    Body { x: a.x + a.reach(n) - n * depth + b.reach(n), ..*b }
}

fn f_ref(a: &Body, b: &Body, n: &V3) -> f64 {
    a.h(n) + b.h(n) - n.dot(&(b.x - a.x))
}

fn gradient_ref(a: &Body, b: &Body, n: &V3) -> V3 {
    a.reach(n) + b.reach(n) - (b.x - a.x)
}

/// Orthonormal tangent basis by Gram–Schmidt (a different construction from the library's).
fn chart(n: &V3) -> (V3, V3) {
    let helper = if n.z.abs() < 0.9 { V3::z() } else { V3::x() };
    let u = (helper - n * n.dot(&helper)).normalize();
    (u, n.cross(&u))
}

/// Local minimum of `f` near `start` on the unit sphere, found by a compass search down to 1e-9
/// rad and, given the gradient `g`, polished by Newton on the tangential gradient with a
/// finite-difference Jacobian (f values alone resolve a minimiser only to √ε).
fn refine(f: &dyn Fn(&V3) -> f64, g: Option<&dyn Fn(&V3) -> V3>, start: V3, spacing: f64) -> (f64, V3) {
    let mut n = start;
    let mut value = f(&n);
    let mut step = spacing;
    let mut budget = 200_000;
    while step > 1e-9 && budget > 0 {
        let (u, v) = chart(&n);
        let moved =
            [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0), (1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)]
                .iter()
                .map(|(du, dv)| (n + (u * *du + v * *dv) * step).normalize())
                .map(|m| (f(&m), m))
                .find(|(fm, _)| *fm < value);
        budget -= 1;
        match moved {
            Some((fm, m)) => (value, n) = (fm, m),
            None => step *= 0.5,
        }
    }
    let Some(g) = g else { return (value, n) };
    for _ in 0..20 {
        let (u, v) = chart(&n);
        let tangential = |du: f64, dv: f64| {
            let m = (n + u * du + v * dv).normalize();
            let gm = g(&m);
            let gt = gm - m * m.dot(&gm);
            Vector2::new(u.dot(&gt), v.dot(&gt))
        };
        let eps = 1e-6;
        let jacobian = Matrix2::from_columns(&[
            (tangential(eps, 0.0) - tangential(-eps, 0.0)) / (2.0 * eps),
            (tangential(0.0, eps) - tangential(0.0, -eps)) / (2.0 * eps),
        ]);
        let Some(delta) = jacobian.lu().solve(&-tangential(0.0, 0.0)) else { break };
        let m = (n + u * delta.x + v * delta.y).normalize();
        // Values resolve a minimiser only to √(ε f / curvature), which in a flat valley leaves the
        // compass search up to ~1e-5 rad off; a polish step may go that far but not climb.
        if f(&m) > value + 1e-13 * (1.0 + value.abs()) || delta.norm() > 1e-3 {
            break;
        }
        (value, n) = (f(&m), m);
        if delta.norm() < 1e-15 {
            break;
        }
    }
    (value, n)
}

/// All local minima of f on the sphere (distinct to 1e-6 rad), lowest first: a 120 × 240
/// latitude–longitude grid (1.5°), every grid point not above its eight neighbours refined.
fn reference_minima(a: &Body, b: &Body) -> Vec<(f64, V3)> {
    const ROWS: usize = 120;
    const COLUMNS: usize = 240;
    let direction = |i: usize, j: usize| {
        let theta = std::f64::consts::PI * (i as f64 + 0.5) / ROWS as f64;
        let phi = std::f64::consts::TAU * j as f64 / COLUMNS as f64;
        V3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
    };
    let values: Vec<f64> = (0..ROWS * COLUMNS).map(|k| f_ref(a, b, &direction(k / COLUMNS, k % COLUMNS))).collect();
    let at = |i: usize, j: usize| values[i * COLUMNS + j % COLUMNS];
    let f = |n: &V3| f_ref(a, b, n);
    let g = |n: &V3| gradient_ref(a, b, n);
    let mut minima: Vec<(f64, V3)> = Vec::new();
    for i in 0..ROWS {
        for j in 0..COLUMNS {
            let here = at(i, j);
            let lowest = (i.saturating_sub(1)..(i + 2).min(ROWS))
                .all(|k| (j + COLUMNS - 1..j + COLUMNS + 2).all(|l| at(k, l) >= here));
            if lowest {
                let found = refine(&f, Some(&g), direction(i, j), std::f64::consts::PI / ROWS as f64);
                match minima.iter_mut().find(|(_, n)| (n - found.1).norm() < 1e-6) {
                    Some(known) if found.0 < known.0 => *known = found,
                    Some(_) => {}
                    None => minima.push(found),
                }
            }
        }
    }
    minima.sort_by(|p, q| p.0.total_cmp(&q.0));
    minima
}

/// The solver stops at a predicted normal error of 1e-11 rad (`ERROR_TARGET`); tests allow ten
/// times that.
const NORMAL_ERROR: f64 = 1e-10;

/// The returned support points lie on both surfaces, δ apart along n, with outward normals n
/// and −n: the touching configuration after B moves by δ n. Checked with the implicit surface,
/// a description the library never uses. A normal error e leaves a tangential gradient of up to
/// (R_A + R_B) e (R = s_max²/s_min, the largest radius of curvature), which is how far the
/// points reconstructed from (point, n, δ) may sit off the surfaces.
fn assert_touching_geometry(a: &Body, b: &Body, c: &ContactGeometry) {
    let scale = (b.x - a.x).norm() + a.axes.max() + b.axes.max();
    let slack = 0.5 * (a.largest_curvature_radius() + b.largest_curvature_radius()) * NORMAL_ERROR + 1e-13 * scale;
    let on_a = c.point + c.normal * (0.5 * c.depth);
    let on_b = c.point - c.normal * (0.5 * c.depth);
    assert!((c.normal.norm() - 1.0).abs() < 1e-14, "normal not unit: {}", c.normal.norm());
    for (body, on, outward) in [(a, on_a, c.normal), (b, on_b, -c.normal)] {
        // The level function grows by at most distance / s_min off the surface, and the surface
        // normal turns by at most distance / ρ along it.
        let off = body.level(&on) - 1.0;
        assert!(off.abs() < slack / body.smallest(), "point off the surface: level − 1 = {off:e}, slack {slack:e}");
        let turn = (body.outward_normal(&on) - outward).norm();
        assert!(turn < slack / body.rolling_radius() + NORMAL_ERROR, "surface normal off by {turn:e}");
    }
}

#[derive(Default, Debug)]
struct Tally {
    separated: usize,
    shallow: usize,
    deep: usize,
    several_minima: usize,
    global_searches: usize,
    worst_depth: f64,
    worst_normal: f64,
    worst_point: f64,
}

/// Compares one pair with the dense reference and tallies what kind of case it was.
fn check_against_reference(a: &Body, b: &Body, tally: &mut Tally) {
    let minima = reference_minima(a, b);
    let (best, best_normal) = minima[0];
    let s = a.smallest().min(b.smallest());
    let (got, stats) = ellipsoid_ellipsoid_with_stats(&a.pose(), &b.pose(), None);
    tally.global_searches += stats.global_search as usize;
    // Within rounding of touching either answer is right.
    if best.abs() < 1e-12 * s {
        return;
    }
    if best < 0.0 {
        assert!(got.is_none(), "separated pair (min f = {best:e}) reported {got:?}: {a:?} {b:?}");
        tally.separated += 1;
        return;
    }
    let c = got.unwrap_or_else(|| panic!("overlap {best:e} missed: {a:?} {b:?}"));
    if best < a.rolling_radius() + b.rolling_radius() {
        tally.shallow += 1;
    } else {
        tally.deep += 1;
    }
    tally.several_minima += (minima.iter().filter(|m| m.0 > 0.0).count() > 1) as usize;
    let depth_error = (c.depth - best).abs() / s;
    // Minima tied to within 1e-9 s are equally valid answers (a symmetric configuration).
    let normal_error =
        minima.iter().filter(|m| m.0 <= best + 1e-9 * s).map(|m| (c.normal - m.1).norm()).fold(f64::INFINITY, f64::min);
    tally.worst_depth = tally.worst_depth.max(depth_error);
    tally.worst_normal = tally.worst_normal.max(normal_error);
    assert!(depth_error < ACCEPTANCE, "depth {} vs reference {best} (error {depth_error:e} s): {a:?} {b:?}", c.depth);
    assert!(
        normal_error < ACCEPTANCE,
        "normal {} vs reference {best_normal} (error {normal_error:e}), minima {minima:?}: {a:?} {b:?}",
        c.normal
    );
    // The point from the reference normal, to which the solver's is held at the accepted tolerance.
    let point_error = minima
        .iter()
        .filter(|m| m.0 <= best + 1e-9 * s)
        .map(|m| (c.point - ((a.x + a.reach(&m.1)) + (b.x - b.reach(&m.1))) * 0.5).norm() / s)
        .fold(f64::INFINITY, f64::min);
    tally.worst_point = tally.worst_point.max(point_error);
    assert!(point_error < ACCEPTANCE, "point off by {point_error:e} s: {a:?} {b:?}");
    assert_touching_geometry(a, b, &c);
}

#[test]
fn random_pairs_match_the_dense_reference() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut tally = Tally::default();
    for _ in 0..400 {
        let (a, b) = random_pair(&mut rng, 1.0, 0.0..1.1);
        check_against_reference(&a, &b, &mut tally);
    }
    eprintln!("random pairs: {tally:?}");
    // The sample must exercise every regime, including the non-convex one with several minima.
    assert!(
        tally.separated >= 10 && tally.shallow >= 10 && tally.deep >= 50 && tally.several_minima >= 10,
        "{tally:?}"
    );
}

#[test]
fn needles_and_plates_match_the_dense_reference() {
    // Extreme shapes make the flattest minima (a spheroid's round section) and the most local
    // minima; every other pair has a partner a hundredth the size.
    let mut rng = ChaCha8Rng::seed_from_u64(15);
    let mut tally = Tally::default();
    for k in 0..200 {
        let scale_b = if k % 2 == 0 { 1.0 } else { 0.01 };
        let a = Body { x: V3::zeros(), r: random_rotation(&mut rng), axes: random_extreme_axes(&mut rng, 1.0) };
        let mut b = Body { x: V3::zeros(), r: random_rotation(&mut rng), axes: random_extreme_axes(&mut rng, scale_b) };
        let m = random_unit(&mut rng);
        b.x = m * (rng.random_range(0.0..1.1) * (a.h(&m) + b.h(&m)));
        check_against_reference(&a, &b, &mut tally);
    }
    eprintln!("needles and plates: {tally:?}");
    // Overlaps below ρ = s_min/10 per body are rare in this draw; the constructed tests cover them.
    assert!(tally.separated >= 10 && tally.shallow >= 5 && tally.deep >= 50 && tally.several_minima >= 10, "{tally:?}");
}

#[test]
fn tiny_and_big_ellipsoids_match_the_dense_reference() {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let mut tally = Tally::default();
    for k in 0..150 {
        // B a hundredth of A, every other time passed first.
        let (a, b) = random_pair(&mut rng, 0.01, 0.0..1.1);
        if k % 2 == 0 {
            check_against_reference(&a, &b, &mut tally);
        } else {
            check_against_reference(&b, &a, &mut tally);
        }
    }
    eprintln!("tiny and big: {tally:?}");
    assert!(tally.separated >= 5 && tally.shallow + tally.deep >= 50, "{tally:?}");
}

#[test]
fn contacts_placed_by_construction_have_the_exact_depth_normal_and_point() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut worst = (0.0f64, 0.0f64);
    for k in 0..400 {
        let scale_b = if k % 4 == 3 { 0.01 } else { 1.0 };
        let a = Body { x: V3::new(0.3, -0.2, 0.1), r: random_rotation(&mut rng), axes: random_axes(&mut rng, 1.0) };
        let b = Body { x: V3::zeros(), r: random_rotation(&mut rng), axes: random_axes(&mut rng, scale_b) };
        let rho = a.rolling_radius() + b.rolling_radius();
        let n = random_unit(&mut rng);
        for fraction in [1e-9, 1e-6, 1e-3, 0.1, 0.5, 0.99] {
            let depth = fraction * rho;
            let b = placed_against(&a, &b, &n, depth);
            let c = ellipsoid_ellipsoid(&a.pose(), &b.pose(), None).expect("overlapping pair missed");
            // f is a difference of terms of size |d| + h, so its rounding is a few ulps of that.
            let scale = (b.x - a.x).norm() + a.axes.max() + b.axes.max();
            let depth_error = (c.depth - depth).abs();
            let normal_error = (c.normal - n).norm();
            worst = (worst.0.max(depth_error / a.smallest().min(b.smallest())), worst.1.max(normal_error));
            assert!(depth_error < 64.0 * f64::EPSILON * scale, "depth {} vs {depth} ({fraction} ρ)", c.depth);
            assert!(normal_error < NORMAL_ERROR, "normal off by {normal_error:e} at {fraction} ρ");
            // A normal error e moves the support points by up to R e (R = s_max²/s_min).
            let curvature = a.largest_curvature_radius() + b.largest_curvature_radius();
            let expected_point = a.x + a.reach(&n) - n * (0.5 * depth);
            assert!(
                (c.point - expected_point).norm() < NORMAL_ERROR * curvature,
                "point {} vs {expected_point}",
                c.point
            );
            // That n is the global minimum rests on the rolling-ball theorem the library uses
            // too, so the dense reference confirms it where it is tightest, just below ρ.
            if k % 10 == 0 && fraction == 0.99 {
                let best = reference_minima(&a, &b)[0].0;
                assert!((best - depth).abs() < 1e-12 * scale, "reference minimum {best} below the placed {depth}");
            }
        }
    }
    eprintln!("constructed contacts: worst depth error {:e} s_min, worst normal error {:e}", worst.0, worst.1);
}

#[test]
fn just_overlapping_pairs_report_a_tiny_depth_and_just_separated_ones_none() {
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    for _ in 0..500 {
        let a = Body { x: V3::zeros(), r: random_rotation(&mut rng), axes: random_axes(&mut rng, 1.0) };
        let b = Body { x: V3::zeros(), r: random_rotation(&mut rng), axes: random_axes(&mut rng, 1.0) };
        let n = random_unit(&mut rng);
        // 1e-10 of the smallest axis is still ~1e5 ulps of the terms of f, so the sign is sound.
        let gap = 1e-10 * a.smallest().min(b.smallest());
        let touching = placed_against(&a, &b, &n, gap);
        let c = ellipsoid_ellipsoid(&a.pose(), &touching.pose(), None).expect("just-overlapping pair missed");
        assert!((c.depth - gap).abs() < 1e-3 * gap, "depth {} for an overlap of {gap}", c.depth);
        let apart = placed_against(&a, &b, &n, -gap);
        assert_eq!(ellipsoid_ellipsoid(&a.pose(), &apart.pose(), None), None, "pair {gap} apart reported in contact");
    }
}

#[test]
fn separated_pairs_with_overlapping_bounding_spheres_give_none() {
    // Parallel needles side by side: bounding spheres of radius 10 overlap, the bodies are 0.5 apart.
    let needle = Body { x: V3::zeros(), r: Matrix3::identity(), axes: V3::new(10.0, 1.0, 1.0) };
    let neighbour = Body { x: V3::new(3.0, 2.5, 0.0), ..needle };
    assert_eq!(ellipsoid_ellipsoid(&needle.pose(), &neighbour.pose(), None), None);
    // A warm normal from an earlier contact must not make a separated pair look overlapping.
    assert_eq!(ellipsoid_ellipsoid(&needle.pose(), &neighbour.pose(), Some(&V3::y())), None);
}

#[test]
fn spheres_match_the_analytic_result() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for _ in 0..1000 {
        let (ra, rb) = (rng.random_range(0.01..1.0), rng.random_range(0.01..1.0));
        let a = Body { x: V3::new(1.0, 2.0, 3.0), r: random_rotation(&mut rng), axes: V3::repeat(ra) };
        let d = random_unit(&mut rng) * rng.random_range(0.01..1.0) * (ra + rb);
        let b = Body { x: a.x + d, r: random_rotation(&mut rng), axes: V3::repeat(rb) };
        let c = ellipsoid_ellipsoid(&a.pose(), &b.pose(), None).expect("overlapping spheres missed");
        let dhat = d.normalize();
        // A rotated sphere's Q is r·R Rᵀ, which equals r·I only to rounding: allow a few ulps.
        let ulps = 16.0 * f64::EPSILON * (ra + rb + d.norm());
        assert!((c.depth - (ra + rb - d.norm())).abs() < ulps, "depth {} vs {}", c.depth, ra + rb - d.norm());
        // That rounding tilts the normal by ulps of (r_A + r_B) over the lever |d|.
        let tilt = 64.0 * f64::EPSILON * (ra + rb) / d.norm();
        assert!((c.normal - dhat).norm() < tilt, "normal {} vs {dhat}", c.normal);
        let point = (a.x + dhat * ra + b.x - dhat * rb) * 0.5;
        assert!((c.point - point).norm() < ulps + (ra + rb) * tilt, "point {} vs {point}", c.point);
    }
}

#[test]
fn swapping_the_bodies_gives_the_same_point_and_depth_and_the_opposite_normal() {
    let mut rng = ChaCha8Rng::seed_from_u64(6);
    let (mut compared, mut searched) = (0, 0);
    for k in 0..2000 {
        let (a, b) = random_pair(&mut rng, if k % 3 == 0 { 0.1 } else { 1.0 }, 0.0..1.1);
        let (pa, pb) = (a.pose(), b.pose());
        let (ab, stats) = ellipsoid_ellipsoid_with_stats(&pa, &pb, None);
        let ba = ellipsoid_ellipsoid(&pb, &pa, None);
        let (Some(ab), Some(ba)) = (ab, ba) else {
            assert_eq!(ab.is_none(), ba.is_none(), "only one order found the contact");
            continue;
        };
        compared += 1;
        searched += stats.global_search as usize;
        // Both orders do the same floating-point operations with signs flipped (module docs),
        // so they agree bit for bit; only exactly tied minima, which random pairs do not have,
        // could tell them apart.
        assert_eq!((ab.point, ab.depth, ab.normal), (ba.point, ba.depth, -ba.normal), "{a:?} {b:?}");
        // Warm starts from mirrored normals mirror each other too.
        let warm_ab = ellipsoid_ellipsoid(&pa, &pb, Some(&ab.normal)).unwrap();
        let warm_ba = ellipsoid_ellipsoid(&pb, &pa, Some(&ba.normal)).unwrap();
        assert_eq!((warm_ab.point, warm_ab.depth, warm_ab.normal), (warm_ba.point, warm_ba.depth, -warm_ba.normal));
    }
    // Both paths must be exercised: the certified Newton runs and the global search.
    assert!(compared > 1000 && searched > 100 && compared - searched > 100, "{compared} compared, {searched} searched");
}

#[test]
fn aligned_twins_offset_along_their_short_axis() {
    // K = A − B is the ellipsoid with doubled axes about −d; it holds the ball of radius 2c, so
    // the nearest boundary point from an offset along the short axis is the short vertex.
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for _ in 0..200 {
        let r = random_rotation(&mut rng);
        let axes = V3::new(rng.random_range(2.0..10.0), rng.random_range(1.0..2.0), 1.0);
        let a = Body { x: V3::new(-1.0, 0.5, 2.0), r, axes };
        let offset = rng.random_range(1e-6..2.0);
        let b = Body { x: a.x + r.column(2) * offset, ..a };
        let c = ellipsoid_ellipsoid(&a.pose(), &b.pose(), None).expect("twins overlapping along the short axis missed");
        // h = √(nᵀQ²n) rounds to (s_max/s_min)² ulps (module docs), here of terms ≤ 4.
        let rounding = 16.0 * axes.x.powi(2) * f64::EPSILON;
        assert!((c.depth - (2.0 - offset)).abs() < rounding, "depth {} vs {}", c.depth, 2.0 - offset);
        assert!((c.normal - r.column(2)).norm() < NORMAL_ERROR, "normal {} vs the short axis", c.normal);
    }
}

#[test]
fn aligned_twins_offset_along_their_long_axis_have_the_ellipse_distance() {
    // K = A − B is the ellipsoid (2a, 2b, 2c) about −d. The origin lies at x0 = |d| on its long
    // axis; the nearest boundary point is in the long–short plane (the ellipse of semi-axes
    // P = 2a, S = 2c): the long vertex when x0 ≥ P − S²/P, else the two mirror points with
    // cos t = x0 P/(P² − S²), one of the configuration's two tied minima.
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let mut pairs_of_minima = 0;
    for _ in 0..200 {
        let r = random_rotation(&mut rng);
        let axes = V3::new(rng.random_range(1.5..10.0), rng.random_range(1.1..1.4), 1.0);
        let a = Body { x: V3::new(2.0, 0.0, -1.0), r, axes };
        let x0 = rng.random_range(0.01..0.99) * 2.0 * axes.x;
        let b = Body { x: a.x + r.column(0) * x0, ..a };
        let c = ellipsoid_ellipsoid(&a.pose(), &b.pose(), None).expect("twins overlapping along the long axis missed");
        let (p, s) = (2.0 * axes.x, 2.0 * axes.z);
        let (depth, normals) = if x0 >= p - s * s / p {
            (p - x0, vec![V3::x()])
        } else {
            pairs_of_minima += 1;
            let cos = x0 * p / (p * p - s * s);
            let sin = (1.0 - cos * cos).sqrt();
            let to_point = Vector2::new(p * cos - x0, s * sin);
            let n = to_point.normalize();
            (to_point.norm(), vec![V3::new(n.x, 0.0, n.y), V3::new(n.x, 0.0, -n.y)])
        };
        // Near x0 = P − S²/P the two minima merge into a quartic one whose normal f64 resolves
        // only to ~ε^(1/4), so the accepted tolerance is the one to hold here.
        let s_min = axes.min();
        assert!((c.depth - depth).abs() < ACCEPTANCE * s_min, "depth {} vs {depth}", c.depth);
        let body_normal = r.transpose() * c.normal;
        let error = normals.iter().map(|n| (body_normal - n).norm()).fold(f64::INFINITY, f64::min);
        assert!(error < ACCEPTANCE, "normal {body_normal} (body frame) is none of {normals:?}");
    }
    assert!(pairs_of_minima > 50, "too few cases with two tied minima: {pairs_of_minima}");
}

#[test]
fn a_warm_start_follows_a_slowly_moving_contact_in_a_few_iterations() {
    // Both grains turn by 1e-3 rad per step and the normal swings by 1e-3 rad, faster than in a
    // settling bed; B is placed by construction so each step's answer is known exactly.
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let mut iterations = Vec::new();
    for _ in 0..50 {
        let mut a = Body { x: V3::zeros(), r: random_rotation(&mut rng), axes: random_axes(&mut rng, 1.0) };
        let mut b = Body { x: V3::zeros(), r: random_rotation(&mut rng), axes: random_axes(&mut rng, 1.0) };
        let (mut qa, mut qb) = (UnitQuaternion::from_matrix(&a.r), UnitQuaternion::from_matrix(&b.r));
        let (spin_a, spin_b, swing) = (random_unit(&mut rng), random_unit(&mut rng), random_unit(&mut rng));
        let mut n = random_unit(&mut rng);
        let rho = a.rolling_radius() + b.rolling_radius();
        let mut warm: Option<V3> = None;
        for step in 0..200 {
            let depth = rho * (0.05 + 0.04 * (step as f64 * 0.05).sin());
            b = placed_against(&a, &b, &n, depth);
            let (c, stats) = ellipsoid_ellipsoid_with_stats(&a.pose(), &b.pose(), warm.as_ref());
            let c = c.expect("persisting contact lost");
            assert!(stats.certified && !stats.global_search, "warm start not certified: {stats:?}");
            assert!((c.normal - n).norm() < NORMAL_ERROR, "normal off by {:e}", (c.normal - n).norm());
            let scale = (b.x - a.x).norm() + a.axes.max() + b.axes.max();
            assert!((c.depth - depth).abs() < 64.0 * f64::EPSILON * scale, "depth off by {:e}", c.depth - depth);
            if warm.is_some() {
                iterations.push(stats.newton_iterations);
            }
            warm = Some(c.normal);
            // Through renormalised quaternions, so that R stays orthogonal to rounding as the
            // reference (which inverts R by Rᵀ) assumes.
            qa = UnitQuaternion::new_normalize((UnitQuaternion::from_scaled_axis(spin_a * 1e-3) * qa).into_inner());
            qb = UnitQuaternion::new_normalize((UnitQuaternion::from_scaled_axis(spin_b * 1e-3) * qb).into_inner());
            (a.r, b.r) = (qa.to_rotation_matrix().into_inner(), qb.to_rotation_matrix().into_inner());
            n = UnitQuaternion::from_scaled_axis(swing.cross(&n).normalize() * 1e-3) * n;
        }
    }
    iterations.sort_unstable();
    let mean = iterations.iter().sum::<u32>() as f64 / iterations.len() as f64;
    eprintln!(
        "warm starts: mean {mean:.2}, median {}, max {} Newton iterations",
        iterations[iterations.len() / 2],
        iterations.last().unwrap()
    );
    // Newton from 1e-3 rad away: one step to ~1e-6, one to ~1e-12 which is below the tolerance.
    assert!(*iterations.last().unwrap() <= 3, "a warm start took {} iterations", iterations.last().unwrap());
}

#[test]
fn cold_starts_on_shallow_contacts_are_certified_without_a_global_search() {
    // For overlaps below ρ_A + ρ_B, Newton from the centre line ends in the unique minimum.
    let mut rng = ChaCha8Rng::seed_from_u64(10);
    let mut iterations = Vec::new();
    for k in 0..2000 {
        let a = Body { x: V3::zeros(), r: random_rotation(&mut rng), axes: random_axes(&mut rng, 1.0) };
        let b = Body {
            x: V3::zeros(),
            r: random_rotation(&mut rng),
            axes: random_axes(&mut rng, if k % 2 == 0 { 1.0 } else { 0.1 }),
        };
        let depth = rng.random_range(1e-4..0.5) * (a.rolling_radius() + b.rolling_radius());
        let b = placed_against(&a, &b, &random_unit(&mut rng), depth);
        let (c, stats) = ellipsoid_ellipsoid_with_stats(&a.pose(), &b.pose(), None);
        // Terms of f up to ~20, rounding to (s_max/s_min)² ≤ 100 ulps through √(nᵀQ²n).
        assert!((c.expect("overlap missed").depth - depth).abs() < 1e-12, "wrong depth");
        assert!(stats.certified, "{stats:?}");
        iterations.push((stats.newton_iterations, stats.global_search));
    }
    let searched = iterations.iter().filter(|i| i.1).count();
    let mut counts: Vec<u32> = iterations.iter().map(|i| i.0).collect();
    counts.sort_unstable();
    eprintln!(
        "cold starts: median {}, 99th percentile {}, max {} Newton iterations; {searched} global searches",
        counts[counts.len() / 2],
        counts[counts.len() * 99 / 100],
        counts.last().unwrap()
    );
    assert!(searched <= 20, "{searched} of 2000 shallow cold starts needed the global search");
}

#[test]
fn support_points_lie_on_the_surface_with_normal_n() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for _ in 0..1000 {
        let body =
            Body { x: random_unit(&mut rng) * 3.0, r: random_rotation(&mut rng), axes: random_axes(&mut rng, 0.5) };
        let pose = body.pose();
        let n = random_unit(&mut rng) * rng.random_range(0.1..10.0);
        let s = pose.support(&n);
        // Exact but for rounding, which √(nᵀQ²n) amplifies by up to (s_max/s_min)² = 100.
        assert!((body.level(&s) - 1.0).abs() < 1e-13, "support point off the surface");
        assert!((body.outward_normal(&s) - n.normalize()).norm() < 1e-12, "surface normal is not n");
        assert_eq!(pose.bounding_radius(), body.axes.max());
        assert_eq!(*pose.center(), body.x);
    }
}

#[test]
fn an_axis_aligned_ellipsoid_on_the_floor() {
    for axes in [V3::new(3.0, 2.0, 1.0), V3::new(1.0, 2.0, 3.0)] {
        let overlap = 0.01;
        let center = V3::new(0.4, -0.7, axes.z - overlap);
        let e = EllipsoidPose::new(center, &Matrix3::identity(), axes);
        let c = ellipsoid_plane(&e, &V3::zeros(), &V3::z()).expect("resting ellipsoid missed");
        // The lowest point is the bottom vertex straight below the centre, `overlap` under z = 0;
        // with Q² diagonal every step is exact but for an ulp.
        assert!((c.depth - overlap).abs() < 1e-15, "depth {}", c.depth);
        assert_eq!(c.normal, -V3::z());
        assert!((c.point - V3::new(0.4, -0.7, -0.5 * overlap)).norm() < 1e-15, "point {}", c.point);
        let lifted = EllipsoidPose::new(center + V3::z() * 2.0 * overlap, &Matrix3::identity(), axes);
        assert_eq!(ellipsoid_plane(&lifted, &V3::zeros(), &V3::z()), None);
    }
}

#[test]
fn a_tilted_ellipsoid_against_planes_reaches_sqrt_m_q2_m() {
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    for _ in 0..1000 {
        let body = Body { x: random_unit(&mut rng), r: random_rotation(&mut rng), axes: random_axes(&mut rng, 0.3) };
        let m = random_unit(&mut rng);
        let plane_point = V3::new(0.1, 0.2, 0.3);
        // The support height sqrt(mᵀ Q² m), computed in the body frame.
        let reach = body.h(&m);
        let depth = reach - (body.x - plane_point).dot(&m);
        let c = ellipsoid_plane(&body.pose(), &plane_point, &m);
        if depth <= 0.0 {
            assert_eq!(c, None, "grain {depth} clear of the plane reported in contact");
            continue;
        }
        let c = c.expect("plane contact missed");
        // Closed form both ways: agreement to ulps of |x − p| + reach ≲ 5, amplified ≤ 100 near
        // the short axis through √(mᵀQ²m).
        assert!((c.depth - depth).abs() < 1e-14, "depth {} vs {depth}", c.depth);
        assert_eq!(c.normal, -m);
        let deepest = c.point - m * (0.5 * depth);
        assert!((body.level(&deepest) - 1.0).abs() < 1e-13, "deepest point off the surface");
        assert!((body.outward_normal(&deepest) + m).norm() < 1e-12, "deepest point's normal is not −m");
        // The other support point lies on the plane.
        assert!((c.point + m * (0.5 * depth) - plane_point).dot(&m).abs() < 1e-14);
    }
}

/// Farthest point from the vertical axis through (ax, ay): the surface x + R diag(axes) u over
/// a 100 × 200 grid of unit u, refined by a compass search (values to rounding, argmax to ~1e-8).
fn reference_farthest(body: &Body, ax: f64, ay: f64) -> (f64, V3) {
    let radial = |u: &V3| {
        let y = body.x + body.r * body.axes.component_mul(u);
        -((y.x - ax).powi(2) + (y.y - ay).powi(2)).sqrt()
    };
    let mut best = (f64::INFINITY, V3::z());
    for i in 0..100 {
        for j in 0..200 {
            let theta = std::f64::consts::PI * (i as f64 + 0.5) / 100.0;
            let phi = std::f64::consts::TAU * j as f64 / 200.0;
            let u = V3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
            let value = radial(&u);
            if value < best.0 {
                best = (value, u);
            }
        }
    }
    let (value, u) = refine(&radial, None, best.1, std::f64::consts::PI / 100.0);
    (-value, body.x + body.r * body.axes.component_mul(&u))
}

#[test]
fn a_sphere_against_the_cylinder_wall() {
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    let (ax, ay, wall) = (0.5, -0.25, 2.0);
    for _ in 0..500 {
        let r = rng.random_range(0.01..0.3);
        let out = random_unit(&mut rng).xy().normalize();
        let rho = rng.random_range(wall - 2.0 * r..wall);
        let center = V3::new(ax + rho * out.x, ay + rho * out.y, rng.random_range(-1.0..1.0));
        let c = ellipsoid_cylinder_wall(
            &EllipsoidPose::new(center, &random_rotation(&mut rng), V3::repeat(r)),
            ax,
            ay,
            wall,
        );
        let depth = rho + r - wall;
        if depth <= 0.0 {
            assert_eq!(c, None);
            continue;
        }
        let c = c.expect("sphere poking out missed");
        // Exact but for ulps of the wall radius 2 (depth, point) and the Newton tolerance (normal).
        let normal = V3::new(out.x, out.y, 0.0);
        assert!((c.depth - depth).abs() < 1e-14, "depth {} vs {depth}", c.depth);
        assert!((c.normal - normal).norm() < 1e-12, "normal {} vs {normal}", c.normal);
        let point = V3::new(ax, ay, center.z) + normal * (wall + 0.5 * depth);
        assert!((c.point - point).norm() < 1e-13, "point {} vs {point}", c.point);
    }
}

#[test]
fn a_needle_radial_or_tangential_against_the_cylinder_wall() {
    let (wall, a, b) = (20.0, 1.0, 0.1);
    let out = V3::new(0.6, 0.8, 0.0);
    let along = V3::new(-0.8, 0.6, 0.0);
    let frame = |long: V3| Matrix3::from_columns(&[long, V3::z().cross(&long), V3::z()]);
    // Closed forms: depths to ulps of the radius 20, normals to the Newton tolerance.
    // Long axis radial: the tip is farthest, depth = r0 + a − R.
    let r0 = wall - a + 0.01;
    let c =
        ellipsoid_cylinder_wall(&EllipsoidPose::new(out * r0, &frame(out), V3::new(a, b, b)), 0.0, 0.0, wall).unwrap();
    assert!((c.depth - 0.01).abs() < 1e-13 && (c.normal - out).norm() < 1e-12, "{c:?}");
    // Long axis tangential, grain small against the wall (r0 ≥ (a² − b²)/b): the radial vertex at
    // r0 + b is farthest.
    let r0 = wall - b + 0.01;
    let c = ellipsoid_cylinder_wall(&EllipsoidPose::new(out * r0, &frame(along), V3::new(a, b, b)), 0.0, 0.0, wall)
        .unwrap();
    assert!((c.depth - 0.01).abs() < 1e-13 && (c.normal - out).norm() < 1e-12, "{c:?}");
    // Long axis tangential, grain long against the wall (r0 < (a² − b²)/b): two mirror points at
    // cos t = b r0/(a² − b²) lie at distance √(a² + r0² a²/(a² − b²)).
    let (wall, a, b, r0): (f64, f64, f64, f64) = (20.0, 10.0, 1.0, 18.0);
    let farthest = (a * a + r0 * r0 * a * a / (a * a - b * b)).sqrt();
    let c = ellipsoid_cylinder_wall(&EllipsoidPose::new(out * r0, &frame(along), V3::new(a, b, b)), 0.0, 0.0, wall)
        .unwrap();
    assert!((c.depth - (farthest - wall)).abs() < 1e-12, "depth {} vs {}", c.depth, farthest - wall);
    let cos = b * r0 / (a * a - b * b);
    let sin = (1.0 - cos * cos).sqrt();
    let normals = [-1.0, 1.0].map(|side| (out * (r0 + b * cos) + along * (side * a * sin)).normalize());
    assert!(normals.iter().any(|n| (c.normal - n).norm() < 1e-10), "normal {} is none of {normals:?}", c.normal);
}

#[test]
fn tilted_grains_against_the_cylinder_wall_match_the_reference() {
    let mut rng = ChaCha8Rng::seed_from_u64(14);
    let (ax, ay, wall) = (1.0, 1.0, 1.0);
    let mut contacts = 0;
    for k in 0..100 {
        // Mostly grains small against the wall, some large enough to need the scan.
        let scale = if k % 5 == 0 { 0.1 } else { 0.01 };
        let axes = random_axes(&mut rng, scale);
        let out = random_unit(&mut rng).xy().normalize();
        let rho = wall - rng.random_range(-0.5..1.0) * axes.max();
        let body = Body { x: V3::new(ax + rho * out.x, ay + rho * out.y, 0.3), r: random_rotation(&mut rng), axes };
        let (farthest, deepest) = reference_farthest(&body, ax, ay);
        let c = ellipsoid_cylinder_wall(&body.pose(), ax, ay, wall);
        let s = axes.min();
        if farthest - wall < -1e-9 * s {
            assert_eq!(c, None, "grain inside the wall reported in contact");
            continue;
        }
        if farthest - wall < 1e-9 * s {
            continue;
        }
        contacts += 1;
        let c = c.expect("grain poking out missed");
        let normal = V3::new(deepest.x - ax, deepest.y - ay, 0.0).normalize();
        assert!((c.depth - (farthest - wall)).abs() < ACCEPTANCE * s, "depth {} vs {}", c.depth, farthest - wall);
        assert!((c.normal - normal).norm() < ACCEPTANCE, "normal {} vs {normal}", c.normal);
        assert!((c.point + c.normal * (0.5 * c.depth) - deepest).norm() < ACCEPTANCE * s, "deepest point");
    }
    assert!(contacts >= 40, "too few contacts: {contacts}");
}
