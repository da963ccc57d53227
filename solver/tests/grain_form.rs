//! Form factors of Table 1 and Eqs. 1, 20–22 against values worked by hand.

use solver::grain::{FormFactor, FormParameters, Undefined};

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs().max(1.0)
}

#[test]
fn table1_factors_of_4_2_1_match_hand_values() {
    // L = 4, I = 2, S = 1, every entry worked out by hand from Table 1.
    let f = FormParameters::new(4.0, 2.0, 1.0).unwrap();
    let expected = [
        (FormFactor::FL, 0.5),
        (FormFactor::EL, 0.5),
        (FormFactor::EQ, 0.25),
        (FormFactor::ASF, 1.0),               // 4·1/2²
        (FormFactor::CSF, 1.0 / 8f64.sqrt()), // 1/sqrt(8)
        (FormFactor::DRI, 2.0 / 3.0),         // (4−2)/(4−1)
        (FormFactor::IFI, 2.5),               // (4+1)/2
        (FormFactor::IRI, 0.75),              // (1+2)/4
        (FormFactor::JFF, 1.0 / 7f64.sqrt()), // 1/sqrt(21/3)
        (FormFactor::KIS, 0.5),               // cbrt(2/16)
        (FormFactor::MPS, 0.5),               // cbrt(1/8)
        (FormFactor::OPI, 20.0 / 3.0),        // 10(2/3 − 1/2)/(1/4)
        (FormFactor::WFI, 3.0),               // 6/2
    ];
    let factors = f.factors();
    for (factor, value) in expected {
        let got = factors.get(factor).unwrap();
        assert!(close(got, value), "{}: {got} vs {value}", factor.symbol());
        assert!(close(factors.inverse(factor).unwrap(), 1.0 / value), "{}⁻¹", factor.symbol());
    }
    assert!(close(f.size(), 2.5f64.sqrt()), "D = sqrt((1 + 4)/2)");
}

#[test]
fn undefined_factors_are_reported_not_nan() {
    let sphere = FormParameters::new(1.0, 1.0, 1.0).unwrap().factors();
    assert_eq!(sphere.get(FormFactor::DRI), Err(Undefined::EqualLongAndShort));
    assert_eq!(sphere.get(FormFactor::OPI), Err(Undefined::EqualLongAndShort));
    assert_eq!(sphere.inverse(FormFactor::DRI), Err(Undefined::EqualLongAndShort));
    assert!(close(sphere.get(FormFactor::WFI).unwrap(), 1.0));
    // L = I: DRI = 0, so its inverse is undefined; OPI = 10(−1/2)/(S/L) = −10.
    let oblate = FormParameters::new(2.0, 2.0, 1.0).unwrap().factors();
    assert_eq!(oblate.get(FormFactor::DRI), Ok(0.0));
    assert_eq!(oblate.inverse(FormFactor::DRI), Err(Undefined::EqualLongAndIntermediate));
    assert!(close(oblate.get(FormFactor::OPI).unwrap(), -10.0));
    // DRI = (3−2)/(3−1) = 1/2 makes OPI = 0 and its inverse undefined.
    let middle = FormParameters::new(3.0, 2.0, 1.0).unwrap().factors();
    assert_eq!(middle.get(FormFactor::OPI), Ok(0.0));
    assert_eq!(middle.inverse(FormFactor::OPI), Err(Undefined::ZeroOpi));
    for (_, x, inv) in middle.iter() {
        for v in [x, inv].into_iter().flatten() {
            assert!(v.is_finite());
        }
    }
}

#[test]
fn invalid_forms_are_refused() {
    assert!(FormParameters::new(1.0, 2.0, 0.5).is_err(), "L < I");
    assert!(FormParameters::new(2.0, 1.0, 1.5).is_err(), "I < S");
    assert!(FormParameters::new(2.0, 1.0, -0.5).is_err(), "negative S");
    assert!(FormParameters::new(f64::NAN, 1.0, 0.5).is_err(), "NaN");
    assert_eq!(FormParameters::from_unsorted([1.0, 3.0, 2.0]).unwrap(), FormParameters::new(3.0, 2.0, 1.0).unwrap());
}

#[test]
fn eqs_20_to_22_give_back_flatness_elongation_and_size() {
    for (fl, el, d) in [(0.5, 0.7, 0.01), (0.1, 0.1, 0.03), (1.0, 1.0, 0.005), (0.647, 0.682, 0.0067)] {
        let f = FormParameters::from_flatness_elongation(fl, el, d);
        let factors = f.factors();
        assert!(close(factors.get(FormFactor::FL).unwrap(), fl));
        assert!(close(factors.get(FormFactor::EL).unwrap(), el));
        assert!(close(f.size(), d));
        assert!(f.l >= f.i && f.i >= f.s);
    }
}
