//! The porosity evaluation of §4.4 against hand-worked cases.

use solver::porosity::{PorosityError, PorositySettings, evaluate};

const MM: f64 = 1e-3;

#[test]
fn simple_cubic_lattice_has_porosity_one_minus_pi_over_six() {
    // Spheres of diameter a = 2 mm touching on a cubic lattice, 5 × 5 per layer in a 10 mm
    // periodic square, 20 layers. Each 1 mm slice holds 25 half-spheres: φ = 25·(π a³/12)/(L² h)
    // = π/6 in every slice below the top, so the bulk is 1 − π/6 exactly.
    let a = 2.0 * MM;
    let mut spheres = Vec::new();
    for layer in 0..20 {
        for _ in 0..25 {
            spheres.push((a / 2.0 + layer as f64 * a, a / 2.0));
        }
    }
    for trim in [2.0 * MM, 3.0 * MM] {
        let p = evaluate(&spheres, (10.0 * MM).powi(2), &PorositySettings { slice: MM, cutoff: 0.5, trim }).unwrap();
        assert!((p.bulk - (1.0 - std::f64::consts::PI / 6.0)).abs() < 1e-12, "bulk {}", p.bulk);
        // The top slice (39 mm–40 mm) is full, the one above empty: the surface is at 40 mm.
        assert!((p.surface - 40.0 * MM).abs() < 1e-12);
        assert!((p.z_minus - trim).abs() < 1e-12 && (p.z_plus - (40.0 * MM - trim)).abs() < 1e-12);
        assert_eq!(p.profile.len(), 41, "ceil(40 mm / 1 mm) + 1 slices");
        assert_eq!(p.profile[40].n, 1.0);
    }
}

#[test]
fn one_sphere_is_split_into_exact_spherical_segments() {
    // r = 1.5 mm at z = 1 mm, slices of 1 mm, area 10 mm²: slice 0 takes the lower half sphere
    // (2.25π mm³, including the part below the floor), slice 1 the segment 0 < u < 1 mm from the
    // centre, π(2.25 − 1/3), slice 2 the cap 1 < u < 1.5 mm, π(1.125 − 2.375/3) = π/3.
    let area = 10.0 * MM * MM;
    let settings = PorositySettings { slice: MM, cutoff: 0.95, trim: 0.0 };
    let p = evaluate(&[(1.0 * MM, 1.5 * MM)], area, &settings).unwrap();
    let pi = std::f64::consts::PI;
    let expected = [2.25 * pi, (2.25 - 1.0 / 3.0) * pi, pi / 3.0, 0.0];
    assert_eq!(p.profile.len(), 4, "ceil(2.5) + 1 slices");
    for (point, v) in p.profile.iter().zip(expected) {
        let solid = (1.0 - point.n) * area * MM / MM.powi(3);
        assert!((solid - v).abs() < 1e-9, "slice at {} mm: {solid} vs {v}", point.z / MM);
    }
    // Solid fractions 0.707, 0.602, 0.105, 0: with n_cut-off = 0.95 (φ = 0.05) the surface is at
    // 3 mm, and all three slices below are averaged.
    assert!((p.surface - 3.0 * MM).abs() < 1e-15);
    let mean = 1.0 - (expected[0] + expected[1] + expected[2]) / 10.0 / 3.0;
    assert!((p.bulk - mean).abs() < 1e-12);
}

#[test]
fn missing_surface_and_overtrimming_are_errors() {
    let area = (10.0 * MM).powi(2);
    // One small sphere never fills half a slice.
    let settings = PorositySettings { slice: MM, cutoff: 0.5, trim: 0.0 };
    assert!(matches!(evaluate(&[(1.0 * MM, 0.5 * MM)], area, &settings), Err(PorosityError::NoSurface(_))));
    assert_eq!(evaluate(&[], area, &settings), Err(PorosityError::Empty));
    let thin: Vec<(f64, f64)> = (0..25).map(|_| (MM, MM)).collect();
    let trimmed = PorositySettings { slice: MM, cutoff: 0.5, trim: 5.0 * MM };
    assert!(matches!(evaluate(&thin, area, &trimmed), Err(PorosityError::TooThin { .. })));
}
