//! The paper's setup as the solver keeps it (§4.2–4.4, §5.1, §6.2, Table 3), the values it
//! derives by rule, and the checks that turn a bad value into an error instead of a panic.

use solver::dem::{Calibration, Domain};
use solver::grain::{FormDistribution, RHINE_FORMS, SieveCurve, Table3Case};
use solver::packing::{DomainKind, FormSpec, Packing, PackingError, PackingSpec, ShapeKind};

#[test]
fn the_paper_setup_derives_height_spacing_time_limit_trim_and_skin_by_its_rules() {
    // Periodic (§6.2): 16 kg of U1 in a 0.2 m square. h_g = 0.016 m (Table 3); the bed of
    // 16/(2650 · 0.04 · 0.6) = 0.2516 m plus two spacings, over 0.6, rounded up to the cm: 0.48 m.
    let periodic = PackingSpec::paper(DomainKind::Periodic);
    assert_eq!(periodic.domain, Domain::Periodic { width: 0.2 });
    assert_eq!((periodic.grains.shape, periodic.grains.mass), (ShapeKind::Ellipsoid, 16.0));
    assert_eq!(periodic.grains.form, FormSpec::Distribution(RHINE_FORMS));
    assert_eq!(periodic.calibration, Calibration::Discrete);
    let d = periodic.derived();
    assert_eq!((d.spacing, d.height, d.max_time), (0.016, 0.48, 66.0));
    // The trim is the largest sieve of the curve (§6.1), the skin 15 % of the smallest in use.
    assert_eq!(d.trim, 0.0315);
    assert!((d.skin - 0.15 * 0.0056).abs() < 1e-18);

    // Cylinder (§5.1): 3 kg, t_s = 1 s, no trim; U7 gives Table 3's h_g = 0.022 m.
    let mut cylinder = PackingSpec::paper(DomainKind::Cylinder);
    assert_eq!(cylinder.domain, Domain::Cylinder { diameter: 0.104 });
    cylinder.grains.size = Table3Case::find("U7").unwrap().sieve_curve();
    let d = cylinder.derived();
    assert_eq!((d.spacing, d.height, d.max_time, d.trim), (0.022, 0.45, 61.0, 0.0));

    // A custom curve has no Table 3 spacing: the largest sieve in use, 8 mm, not the 11.2 mm
    // sieve of its empty last class.
    cylinder.grains.size = SieveCurve::new(vec![0.004, 0.0056, 0.008, 0.0112], vec![0.0, 1.0, 0.0]).unwrap();
    assert_eq!(cylinder.grains.size.case(), None);
    assert_eq!((cylinder.grains.size.smallest_in_use(), cylinder.grains.size.largest_in_use()), (0.0056, 0.008));
    assert_eq!(cylinder.derived().spacing, 0.008);
    // Given values are kept.
    cylinder.height = Some(0.3);
    cylinder.process.spacing = Some(0.01);
    assert_eq!((cylinder.derived().height, cylinder.derived().spacing), (0.3, 0.01));
}

#[test]
fn bad_values_are_errors_naming_the_key_not_panics() {
    let error = |change: fn(&mut PackingSpec)| {
        let mut spec = PackingSpec::paper(DomainKind::Periodic);
        change(&mut spec);
        let Err(PackingError::Spec(e)) = Packing::new(spec.clone()) else { panic!("accepted") };
        assert_eq!(spec.check(), Err(e.clone()));
        e.to_string()
    };
    let e = error(|s| s.grains.form = FormSpec::Single { fl: 0.0, el: 0.5 });
    assert!(e.starts_with("grains.form.fl: 0 is out of range"), "{e}");
    let e = error(|s| {
        s.grains.form =
            FormSpec::Distribution(FormDistribution { mu_fl: 0.6, sigma_fl: -0.1, mu_el: 0.7, sigma_el: 0.1 })
    });
    assert!(e.starts_with("grains.form: sigma_fl = -0.1"), "{e}");
    let e = error(|s| s.grains.form = FormSpec::Own);
    assert!(e.contains("needs grains.shape: mesh"), "{e}");
    let e = error(|s| s.grains.shape = ShapeKind::Mesh);
    assert!(e.starts_with("grains.meshes"), "{e}");
    let e = error(|s| s.time_step = 1e-4);
    assert!(e.contains("solver.time_step") && e.contains("collision_time / 10"), "{e}");
    let e = error(|s| s.process.spacing = Some(1e-9));
    assert!(e.contains("smallest sieve in use, 0.0056 m"), "{e}");
    let e = error(|s| s.material.gravity.z = 3.0);
    assert!(e.starts_with("material.gravity: -3"), "{e}");
    let e = error(|s| s.process.interval = 1e-7);
    assert!(e.starts_with("process.convergence.interval"), "{e}");

    // A distribution built field by field is checked before it is drawn from.
    let bad = FormDistribution { mu_fl: 5.0, sigma_fl: 0.0, mu_el: 0.7, sigma_el: 0.1 };
    assert!(bad.sampler().is_err());
}
