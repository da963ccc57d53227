//! Populations of grains: sieve-curve sizes (§3.2, Eqs. 8–9, Table 3), form distributions
//! (§7.1, §7.3) and generated pebbles, checked against independent computations.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use solver::grain::pebble::{pebble, pebble_library};
use solver::grain::{DistributionError, FormDistribution, SieveCurve, SizeError, TABLE3};

#[test]
fn number_weights_follow_eqs_8_and_9() {
    // Classes 1–2 mm and 2–4 mm with equal mass: d̄ = sqrt(2) and sqrt(8) mm (Eq. 8), so the
    // grain numbers (Eq. 9) are in the ratio (sqrt(8)/sqrt(2))³ = 8 : 1.
    let curve = SieveCurve::new(vec![1e-3, 2e-3, 4e-3], vec![0.5, 0.5]).unwrap();
    let w = curve.number_weights();
    assert!((w[0] - 8.0 / 9.0).abs() < 1e-12 && (w[1] - 1.0 / 9.0).abs() < 1e-12);
    // Eq. 9 in absolute terms: 1 kg of quartz in the 1–2 mm class is 0.5/(2650 π (sqrt2 mm)³/6).
    let n = curve.grain_numbers(1.0, 2650.0);
    let expected = 0.5 / (2650.0 * std::f64::consts::PI * (2f64.sqrt() * 1e-3).powi(3) / 6.0);
    assert!((n[0] - expected).abs() < 1e-9 * expected);
}

#[test]
fn sampled_mass_fractions_match_all_seven_table3_cases() {
    for case in TABLE3 {
        let curve = case.sieve_curve();
        let sieves = curve.sieves();
        let weights = curve.number_weights();
        // Expected mass fractions of the sampler, worked independently: class i is drawn with its
        // number weight w_i and D log-uniform in [a, b], so E[D³] = (b³ − a³)/(3 ln(b/a)).
        let mean_cube: Vec<f64> = (0..curve.classes())
            .map(|i| {
                let (a, b) = (sieves[i], sieves[i + 1]);
                (b.powi(3) - a.powi(3)) / (3.0 * (b / a).ln())
            })
            .collect();
        let total: f64 = (0..curve.classes()).map(|i| weights[i] * mean_cube[i]).sum();

        let sampler = curve.sampler();
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let count = 200_000;
        let draws: Vec<(usize, f64)> = (0..count).map(|_| sampler.sample(&mut rng)).collect();
        let mass: f64 = draws.iter().map(|(_, d)| d.powi(3)).sum();
        for i in 0..curve.classes() {
            let expected = weights[i] * mean_cube[i] / total;
            let mut in_class = 0.0;
            let mut spread = 0.0;
            for &(c, d) in &draws {
                assert!(d >= sieves[c] && d <= sieves[c + 1], "{}: size outside its class", case.name);
                in_class += if c == i { d.powi(3) } else { 0.0 };
            }
            let sampled = in_class / mass;
            // Standard error of a ratio estimator: sqrt(Var(m (1_i − f)) / N) / E[m].
            for &(c, d) in &draws {
                let x = d.powi(3) * (if c == i { 1.0 } else { 0.0 } - sampled);
                spread += x * x;
            }
            let se = (spread / count as f64).sqrt() / (count as f64).sqrt() / (mass / count as f64);
            assert!(
                (sampled - expected).abs() <= 5.0 * se + 1e-12,
                "{} class {i}: {sampled} vs {expected} (se {se})",
                case.name
            );
            // The log-uniform draw inside a class shifts mass fractions by well under 1 %.
            assert!(
                (sampled - case.fractions[i]).abs() < 0.01,
                "{} class {i}: {sampled} vs prescribed {}",
                case.name,
                case.fractions[i]
            );
            if case.fractions[i] == 0.0 {
                assert_eq!(in_class, 0.0, "empty classes are never drawn");
            }
        }
    }
}

#[test]
fn bad_sieve_curves_are_refused() {
    assert_eq!(SieveCurve::new(vec![1e-3, 2e-3, 4e-3], vec![0.5, 0.4]), Err(SizeError::Sum(0.9)));
    assert!(matches!(
        SieveCurve::new(vec![1e-3, 2e-3, 4e-3], vec![1.2, -0.2]),
        Err(SizeError::NegativeFraction { index: 1, .. })
    ));
    assert!(matches!(
        SieveCurve::new(vec![1e-3, 4e-3, 2e-3], vec![0.5, 0.5]),
        Err(SizeError::Unsorted { index: 2, .. })
    ));
    assert!(matches!(SieveCurve::new(vec![1e-3, 2e-3], vec![0.5, 0.5]), Err(SizeError::CountMismatch { .. })));
    assert!(SieveCurve::new(vec![1e-3, 2e-3, 4e-3], vec![0.5, 0.5 + 5e-7]).is_ok(), "within 1e-6 of 1");
    assert!(matches!(SieveCurve::preset("U9"), Err(SizeError::UnknownCase(_))));
    assert_eq!(SieveCurve::preset("b50").unwrap().largest_sieve(), 31.5e-3);
}

/// Raw moments of N(μ, σ) truncated to [0.1, 1] by the trapezoidal rule on 200,000 intervals,
/// independent of the library's integration.
fn truncated(mu: f64, sigma: f64) -> (f64, f64) {
    let n = 200_000;
    let h = 0.9 / n as f64;
    let (mut z, mut m1, mut m2) = (0.0, 0.0, 0.0);
    for k in 0..=n {
        let x = 0.1 + k as f64 * h;
        let w = if k == 0 || k == n { 0.5 } else { 1.0 } * (-0.5 * ((x - mu) / sigma).powi(2)).exp();
        z += w;
        m1 += w * x;
        m2 += w * x * x;
    }
    (m1 / z, (m2 / z - (m1 / z).powi(2)).sqrt())
}

#[test]
fn sampled_forms_follow_the_truncated_normals() {
    for (mu_fl, s_fl, mu_el, s_el) in [(0.647, 0.175, 0.682, 0.139), (0.4, 0.2, 0.8, 0.2), (0.9, 0.3, 0.15, 0.1)] {
        let dist = FormDistribution::new(mu_fl, s_fl, mu_el, s_el).unwrap();
        let sampler = dist.sampler().unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let count = 100_000;
        let pairs: Vec<(f64, f64)> = (0..count).map(|_| sampler.sample_flatness_elongation(&mut rng)).collect();
        let stats = |xs: &mut dyn Iterator<Item = f64>| {
            let v: Vec<f64> = xs.collect();
            let m = v.iter().sum::<f64>() / v.len() as f64;
            (m, (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / v.len() as f64).sqrt())
        };
        let (m_fl, sd_fl) = stats(&mut pairs.iter().map(|p| p.0));
        let (m_el, sd_el) = stats(&mut pairs.iter().map(|p| p.1));
        assert!(pairs.iter().all(|&(f, e)| (0.1..=1.0).contains(&f) && (0.1..=1.0).contains(&e)));
        for (got_m, got_s, (mu, sigma)) in [(m_fl, sd_fl, (mu_fl, s_fl)), (m_el, sd_el, (mu_el, s_el))] {
            let (m, s) = truncated(mu, sigma);
            let se = s / (count as f64).sqrt();
            // Mean within 5 standard errors; std within 5 of its standard error (≈ s/sqrt(2N)).
            assert!((got_m - m).abs() < 5.0 * se, "mean {got_m} vs {m}");
            assert!((got_s - s).abs() < 5.0 * s / (2.0 * count as f64).sqrt(), "std {got_s} vs {s}");
        }
        let moments = dist.truncated_moments();
        assert!((moments.mean_fl - truncated(mu_fl, s_fl).0).abs() < 1e-7);
        assert!((moments.std_el - truncated(mu_el, s_el).1).abs() < 1e-7);
        let m_eq = pairs.iter().map(|(f, e)| f * e).sum::<f64>() / count as f64;
        assert!((m_eq - moments.mean_eq).abs() < 5.0 * moments.std_eq / (count as f64).sqrt());
    }
}

#[test]
fn equancy_statistics_under_independence() {
    // §7.3 with the Rhine values of Table 2, worked by hand:
    // μ_EQ = 0.682 · 0.647 = 0.441254;
    // σ_EQ² = (0.682² + 0.139²)(0.647² + 0.175²) − 0.441254² = 0.0229240726…
    let dist = FormDistribution::new(0.647, 0.175, 0.682, 0.139).unwrap();
    let (mu, sigma) = dist.equancy_statistics();
    assert!((mu - 0.441254).abs() < 1e-12);
    let var = (0.682f64.powi(2) + 0.139f64.powi(2)) * (0.647f64.powi(2) + 0.175f64.powi(2)) - 0.441254f64.powi(2);
    assert!((sigma - var.sqrt()).abs() < 1e-12 && (sigma - 0.1514070).abs() < 1e-6);
}

#[test]
fn bad_form_distributions_are_refused() {
    assert_eq!(
        FormDistribution::new(0.6, -0.1, 0.7, 0.1),
        Err(DistributionError::Sigma { name: "sigma_fl", value: -0.1 })
    );
    assert_eq!(FormDistribution::new(1.2, 0.1, 0.7, 0.1), Err(DistributionError::Mean { name: "mu_fl", value: 1.2 }));
    assert!(FormDistribution::new(0.6, 0.1, 0.05, 0.1).is_err());
    assert!(FormDistribution::new(0.6, 0.1, f64::NAN, 0.1).is_err());
}

#[test]
fn pebbles_are_closed_convex_bounded_and_reproducible() {
    let library = pebble_library(12, 3, 300).unwrap();
    let mut flatness = Vec::new();
    for mesh in &library {
        // Within the bound, and as close to it as the scans simplified to it (270 and 300
        // faces): Table 4 has coarser grains pack looser.
        assert!((270..=300).contains(&mesh.triangles().len()), "{} faces", mesh.triangles().len());
        // Convex: no vertex lies outside any face plane.
        for t in 0..mesh.triangles().len() {
            let [a, b, c] = mesh.triangle(t);
            let n = (b - a).cross(&(c - a)).normalize();
            assert!(mesh.vertices().iter().all(|v| n.dot(&(v - a)) < 1e-9));
        }
        let form = solver::grain::EquivalentEllipsoid::of(&mesh.mass_properties()).form().unwrap();
        flatness.push(form.s / form.i);
    }
    // Own forms spread like natural gravel rather than all alike.
    let spread = flatness.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
        - flatness.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!(spread > 0.15, "flatness spread {spread}");
    assert_eq!(pebble(5, 300).unwrap(), pebble(5, 300).unwrap());
    assert_ne!(pebble(5, 300).unwrap(), pebble(6, 300).unwrap());
    assert!(pebble(9, 50).unwrap().triangles().len() <= 50);
}

#[test]
fn angularity_of_a_cube_and_of_a_fine_ellipsoid() {
    use rand::RngExt;
    use solver::grain::{Angularity, TriMesh};
    use std::f64::consts::PI;
    // A cube of side s: sphericity (36π)^(1/3)/6; its inertia is isotropic, so its equivalent
    // ellipsoid is a sphere with 2r²/5 = s²/6 (sphericity 1, volume (4/3)π (5/12)^(3/2) s³).
    let corners: Vec<_> = (0..8)
        .map(|k| nalgebra::Vector3::new((k & 1) as f64, (k >> 1 & 1) as f64, (k >> 2 & 1) as f64) * 2.0)
        .collect();
    let cube = Angularity::of(&TriMesh::convex_hull(&corners).unwrap()).unwrap();
    let want = (36.0 * PI).cbrt() / 6.0;
    assert!((cube.sphericity - want).abs() < 1e-12, "{cube:?}");
    assert!((cube.ellipsoid_sphericity - 1.0).abs() < 1e-12);
    assert!((cube.volume_ratio - 1.0 / (4.0 / 3.0 * PI * (5.0f64 / 12.0).powf(1.5))).abs() < 1e-12);
    assert!((cube.relative_sphericity() - want).abs() < 1e-12);
    // Its largest facet is one of six equal faces; so is a 2 × 4 × 6 box's with the form removed
    // (a cube again: a box's equivalent ellipsoid has semi-axes in proportion to its sides), where
    // at its own form its 4 × 6 face holds 24/88 of the surface.
    assert!((cube.largest_facet - 1.0 / 6.0).abs() < 1e-12, "{cube:?}");
    let block: Vec<_> = corners.iter().map(|c| c.component_mul(&nalgebra::Vector3::new(1.0, 2.0, 3.0))).collect();
    let block = Angularity::of(&TriMesh::convex_hull(&block).unwrap()).unwrap();
    assert!((block.largest_facet - 1.0 / 6.0).abs() < 1e-12, "{block:?}");
    // Its corners lie √3 s/2 from the centre, 3/√5 sphere radii; the box's alike with the form removed.
    assert!((cube.farthest_vertex - 3.0 / 5f64.sqrt()).abs() < 1e-12, "{cube:?}");
    assert!((block.farthest_vertex - 3.0 / 5f64.sqrt()).abs() < 1e-12, "{block:?}");
    // The hull of 4,000 points on an ellipsoid of axes 1 : 0.6 : 0.3: an inscribed polyhedron
    // whose surface and volume differ from the ellipsoid's by O(1/N) relative (N vertices), a
    // few parts in 10³ here; its relative sphericity is 1 to within that.
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let points: Vec<_> = (0..4000)
        .map(|_| {
            let u = loop {
                let v = nalgebra::Vector3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                if v.norm() > 1e-3 && v.norm() <= 1.0 {
                    break v.normalize();
                }
            };
            u.component_mul(&nalgebra::Vector3::new(1.0, 0.6, 0.3))
        })
        .collect();
    let fine = Angularity::of(&TriMesh::convex_hull(&points).unwrap()).unwrap();
    assert!((fine.relative_sphericity() - 1.0).abs() < 5e-3, "{fine:?}");
    assert!((fine.volume_ratio - 1.0).abs() < 5e-3, "{fine:?}");
    // With the form removed the hull is a sphere's, on which a facet holds the triangles whose
    // normals lie within 3° of one: a cap of (1 − cos 3°)/2 = 0.07 % of the surface, plus the
    // hull's largest triangles, which span the largest gap the random points leave, about
    // ln N / N = 0.2 % of the sphere for N = 4,000. A facet chained across the smoothly curved
    // surface would hold many times more.
    assert!(fine.largest_facet < 0.005, "{fine:?}");
    // Every vertex lies on the ellipsoid, whose inscribed hull's equivalent ellipsoid is smaller
    // by the same few parts in 10³.
    assert!((fine.farthest_vertex - 1.0).abs() < 5e-3, "{fine:?}");
    assert!((fine.form.i / fine.form.l - 0.6).abs() < 5e-3 && (fine.form.s / fine.form.i - 0.5).abs() < 5e-3);
}

#[test]
fn generated_pebbles_are_like_the_rhine_scans_in_sphericity_bulk_facets_and_tips() {
    use solver::grain::{Angularity, rhine_meshes, simplify};
    // Both libraries as packings use them: at most 300 faces. Each mean must match the scans'
    // within half the difference of the two scans; the largest facet, where the two scans lie
    // only 0.005 apart, within 0.015 (twice the standard error of 20 pebbles, 0.026 / √20).
    // Pebbles once had 0.968 against the scans' 0.946 in relative sphericity (rounder in their
    // facets); later the scans' sphericity but 0.967 of their ellipsoid's volume against 0.941
    // (angular only in facets, ellipsoids in bulk); later the scans' volume ratio but a planar
    // fracture face (largest facet 0.136 against 0.080) and tips reaching 1.29 of the
    // ellipsoid's semi-axis against 1.24, at a relative sphericity of 0.935: each packed
    // looser than the scans at the same forms.
    let measure = |mesh: &solver::grain::TriMesh| Angularity::of(&simplify(mesh, 300).unwrap().mesh).unwrap();
    let scans: Vec<Angularity> = rhine_meshes().iter().map(|(_, m)| measure(m)).collect();
    let pebbles: Vec<Angularity> = pebble_library(20, 1, 300).unwrap().iter().map(measure).collect();
    let mean = |v: &[Angularity], f: fn(&Angularity) -> f64| v.iter().map(f).sum::<f64>() / v.len() as f64;
    let half_gap = |f: fn(&Angularity) -> f64| 0.5 * (f(&scans[0]) - f(&scans[1])).abs();
    let differs = |f: fn(&Angularity) -> f64| (mean(&pebbles, f) - mean(&scans, f)).abs();
    let sphericity: fn(&Angularity) -> f64 = Angularity::relative_sphericity;
    let volume: fn(&Angularity) -> f64 = |a| a.volume_ratio;
    let facet: fn(&Angularity) -> f64 = |a| a.largest_facet;
    let reach: fn(&Angularity) -> f64 = |a| a.farthest_vertex;
    let show = |v: &[Angularity]| -> Vec<[f64; 4]> {
        v.iter().map(|m| [sphericity(m), volume(m), facet(m), reach(m)]).collect()
    };
    let (p, s) = (show(&pebbles), show(&scans));
    assert!(differs(sphericity) < half_gap(sphericity), "pebbles {p:?}, scans {s:?}");
    assert!(differs(volume) < half_gap(volume), "pebbles {p:?}, scans {s:?}");
    assert!(differs(facet) < 0.015, "pebbles {p:?}, scans {s:?}");
    assert!(differs(reach) < half_gap(reach), "pebbles {p:?}, scans {s:?}");
    // Every pebble is more angular than an ellipsoid by more than a fine mesh of one is (above
    // 0.995, `angularity_of_a_cube_and_of_a_fine_ellipsoid`), by twice that at the least.
    assert!(pebbles.iter().all(|m| sphericity(m) < 0.99), "{p:?}");
}

#[test]
fn a_packings_grains_are_counted_and_weighed_per_sieve_class_of_their_curve() {
    let u3 = SieveCurve::preset("U3").unwrap();
    // Two grains in 5.6–8 mm, one in 8–11.2 mm, none in 11.2–16 mm (asked 0.21), one in
    // 2.8–4 mm (asked 0: still listed, as it holds a grain).
    let drawn = u3.drawn([(2, 1e-3), (3, 4e-3), (2, 2e-3), (0, 5e-4)]);
    let rows: Vec<(f64, f64, f64, usize, f64)> =
        drawn.iter().map(|c| (c.lower, c.upper, c.asked, c.grains, c.mass)).collect();
    assert_eq!(
        rows,
        [
            (2.8e-3, 4.0e-3, 0.0, 1, 5e-4),
            (5.6e-3, 8.0e-3, 0.21, 2, 3e-3),
            (8.0e-3, 11.2e-3, 0.58, 1, 4e-3),
            (11.2e-3, 16.0e-3, 0.21, 0, 0.0),
        ]
    );
}
