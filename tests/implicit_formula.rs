//! The formula language: parsing (with errors at the column), point values, gradients, and
//! the guaranteed enclosure of interval evaluation, as a property over random formulas.

use proptest::prelude::*;
use voxelkit::Error;
use voxelkit::implicit::{
    BoxTest, Coordinates, Dual, Formula, Interval, Split, ThetaRange, test_box,
};

fn value(text: &str, at: [f64; 3]) -> f64 {
    Formula::parse(text, Coordinates::Cartesian)
        .unwrap()
        .tape
        .eval(at)
}

#[test]
fn formulas_evaluate_as_written() {
    let at = [0.5, -2.0, 3.0];
    assert_eq!(value("x^2 + y^2 + z^2 - 1", at), 0.25 + 4.0 + 9.0 - 1.0);
    assert_eq!(value("-x^2", at), -0.25);
    assert_eq!(value("2^-2 * x", at), 0.125);
    assert_eq!(value("y^(3)", at), -8.0);
    assert_eq!(value("1 - 2 - 3", at), -4.0);
    assert_eq!(value("12 / 3 / 2", at), 2.0);
    assert_eq!(
        value("min(x, y) + max(x, z) + abs(y)", at),
        -2.0 + 3.0 + 2.0
    );
    assert_eq!(value("a = x + 1; b = a * a; b - a", at), 2.25 - 1.5);
    assert_eq!(value("1.5e1 + .5", at), 15.5);
    assert!((value("sin(pi / 2) + cos(0) + atan2(1, 1) * 4 / pi", at) - 3.0).abs() < 1e-15);
    assert!((value("exp(log(z)) + sqrt(16) + tan(0)", at) - 7.0).abs() < 1e-14);
    let spherical = Formula::parse("sin(3*theta)*sin(4*phi) - r", Coordinates::Spherical).unwrap();
    assert!(
        (spherical.tape.eval([0.25, 0.5, 0.125]) - ((1.5f64).sin() * 0.5f64.sin() - 0.25)).abs()
            < 1e-15
    );
    let cylindrical = Formula::parse(
        "r - (0.8 + 0.05*sin(32*theta)) + 0*y",
        Coordinates::Cylindrical,
    )
    .unwrap();
    assert!((cylindrical.tape.eval([0.8, 0.0, 7.0])).abs() < 1e-15);
}

fn column_of(text: &str, coords: Coordinates) -> (usize, String) {
    match Formula::parse(text, coords) {
        Err(Error::Formula {
            column, message, ..
        }) => (column, message),
        other => panic!("{text}: expected a formula error, got {other:?}"),
    }
}

#[test]
fn errors_point_at_the_column() {
    let c = Coordinates::Cartesian;
    assert_eq!(column_of("x + * y", c).0, 5);
    let (col, msg) = column_of("x + foo(y)", c);
    assert_eq!(col, 5);
    assert!(
        msg.contains("unknown name `foo`") && msg.contains("x y z"),
        "{msg}"
    );
    let (col, msg) = column_of("x^1.5", c);
    assert_eq!(col, 3);
    assert!(msg.contains("integer powers"), "{msg}");
    assert!(column_of("sin x", c).1.contains("parentheses"));
    assert!(column_of("min(x)", c).1.contains("takes 2 arguments"));
    assert!(column_of("", c).1.contains("empty"));
    assert_eq!(column_of("(x + y", c), (7, "expected `)`".to_string()));
    assert!(column_of("x y", c).1.contains("after the formula"));
    assert_eq!(column_of("x # y", c).0, 3);
    let (col, msg) = column_of("psi - 1", c);
    assert_eq!(col, 1);
    assert!(msg.contains("`psi`"), "{msg}");
    assert!(
        column_of("sin = 2; sin", c)
            .1
            .contains("cannot be redefined")
    );
    // The rendered message shows the formula and a caret under the column.
    let e = Formula::parse("x + * y", c).unwrap_err().to_string();
    assert!(
        e.contains("column 5") && e.contains("x + * y\n      ^"),
        "{e}"
    );
}

/// Stolte & Kaufman blend coordinate systems in one formula: every system's variables are
/// there in every formula, and equal the conversions of the same point.
#[test]
fn coordinates_blend() {
    let mut rng = voxelkit::mesh::generate::SplitMix64(5);
    for _ in 0..200 {
        let p = [
            rng.range(-2.0, 2.0),
            rng.range(-2.0, 2.0),
            rng.range(-2.0, 2.0),
        ];
        for range in [ThetaRange::Positive, ThetaRange::Symmetric] {
            let eval = |text: &str, c: Coordinates| {
                let f = Formula::parse_in(text, c, range).unwrap();
                f.tape.eval(f.coordinates_of(p))
            };
            let spherical = Formula::parse_in("0", Coordinates::Spherical, range)
                .unwrap()
                .coordinates_of(p);
            let cylindrical = Formula::parse_in("0", Coordinates::Cylindrical, range)
                .unwrap()
                .coordinates_of(p);
            let close = |a: f64, b: f64, what: &str| {
                assert!((a - b).abs() < 1e-12, "{what} at {p:?}: {a} vs {b}")
            };
            // r theta phi in a Cartesian formula.
            for (k, name) in ["r", "theta", "phi"].iter().enumerate() {
                close(eval(name, Coordinates::Cartesian), spherical[k], name);
            }
            // x y z in spherical and cylindrical formulas; phi in a cylindrical one.
            for (k, name) in ["x", "y", "z"].iter().enumerate() {
                close(eval(name, Coordinates::Spherical), p[k], name);
                close(eval(name, Coordinates::Cylindrical), p[k], name);
            }
            close(
                eval("phi", Coordinates::Cylindrical),
                cylindrical[2].atan2(cylindrical[0]),
                "cylindrical phi",
            );
            // A named sub-expression may take a blended name for itself.
            close(
                eval("r = 2*x; r", Coordinates::Cartesian),
                2.0 * p[0],
                "named r",
            );
        }
    }
}

/// Random formulas over x, y, z (and the blended r, theta, phi) using every operation.
fn formula() -> impl Strategy<Value = String> {
    formula_over(&["x", "y", "z", "r", "theta", "phi"])
}

/// Random formulas over `variables` using every operation.
fn formula_over(variables: &'static [&'static str]) -> impl Strategy<Value = String> {
    let leaf = prop_oneof![
        prop::sample::select(variables).prop_map(str::to_string),
        (-3.0f64..3.0).prop_map(|c| format!("({c})")),
    ];
    leaf.prop_recursive(5, 40, 2, |inner| {
        prop_oneof![
            (
                inner.clone(),
                inner.clone(),
                prop::sample::select(vec!["+", "-", "*", "/"])
            )
                .prop_map(|(a, b, op)| format!("({a} {op} {b})")),
            (inner.clone(), -3i32..5).prop_map(|(a, n)| format!("({a})^({n})")),
            (
                inner.clone(),
                prop::sample::select(vec!["sqrt", "abs", "sin", "cos", "tan", "exp", "log", "-"])
            )
                .prop_map(|(a, f)| format!("{f}({a})")),
            (
                inner.clone(),
                inner,
                prop::sample::select(vec!["atan2", "min", "max"])
            )
                .prop_map(|(a, b, f)| format!("{f}({a}, {b})")),
        ]
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// Every point of the box evaluates inside the interval of the box.
    #[test]
    fn interval_evaluation_encloses_every_point(
        text in formula(),
        lo in prop::array::uniform3(-4.0f64..4.0),
        size in prop::array::uniform3(0.0f64..3.0),
        samples in prop::collection::vec(prop::array::uniform3(0.0f64..=1.0), 32),
    ) {
        let f = Formula::parse(&text, Coordinates::Cartesian).unwrap();
        let boxed: [Interval; 3] = std::array::from_fn(|k| Interval::new(lo[k], lo[k] + size[k]));
        let range = f.tape.eval(boxed);
        let corners = (0..8).map(|c| std::array::from_fn(|k| if c >> k & 1 == 1 { 1.0 } else { 0.0 }));
        for t in samples.into_iter().chain(corners) {
            let p: [f64; 3] = std::array::from_fn(|k| lo[k] + size[k] * t[k]);
            let v = f.tape.eval(p);
            if v.is_nan() {
                continue;
            }
            prop_assert!(range.contains(v), "{text} at {p:?} = {v}, outside {range:?}");
        }
    }

    /// Forward-mode derivatives agree with central differences where the formula is smooth.
    #[test]
    fn gradients_match_finite_differences(text in formula(), p in prop::array::uniform3(-2.0f64..2.0)) {
        let f = Formula::parse(&text, Coordinates::Cartesian).unwrap();
        let d = f.tape.eval(std::array::from_fn(|k| Dual::variable(p[k], k)));
        prop_assert!(d.value.to_bits() == f.tape.eval(p).to_bits() || d.value.is_nan());
        let h = 1e-6;
        for k in 0..3 {
            let at = |step: f64| {
                let mut x = p;
                x[k] += step;
                f.tape.eval(x)
            };
            let (fa, fb, fp) = (at(-h), at(h), at(0.0));
            let numeric = (fb - fa) / (2.0 * h);
            let coarse = (at(4.0 * h) - at(-4.0 * h)) / (8.0 * h);
            // Skip kinks, poles and large values (where rounding swamps the difference), and
            // places where the two steps disagree: rounding inside the formula swamps the
            // difference there too (a huge term beside a small one, as y^-3 near 0 beside
            // atan2(z, x) under a sine).
            let second = (fb - 2.0 * fp + fa).abs() / (h * h);
            let large = [fa, fb, fp, numeric].iter().any(|v| v.abs() > 1e4);
            let unsteady = (numeric - coarse).abs() > 1e-5 * (1.0 + numeric.abs());
            if !numeric.is_finite() || !d.grad[k].is_finite() || second > 1e3 || large || unsteady {
                continue;
            }
            prop_assert!((numeric - d.grad[k]).abs() <= 1e-4 * (1.0 + numeric.abs()),
                "{text} at {p:?}: d/d{k} = {} vs {numeric}", d.grad[k]);
        }
    }
}

/// Boxes and points for the conversion property: a Cartesian box, and points in it.
fn box_and_points() -> impl Strategy<Value = ([f64; 3], [f64; 3], Vec<[f64; 3]>)> {
    (
        prop::array::uniform3(-2.0f64..2.0),
        prop::array::uniform3(0.001f64..2.0),
        prop::collection::vec(prop::array::uniform3(0.0f64..=1.0), 8),
    )
}

fn check_conversion(
    coords: Coordinates,
    text: &str,
    lo: [f64; 3],
    size: [f64; 3],
    samples: Vec<[f64; 3]>,
) -> Result<(), TestCaseError> {
    for theta_range in [ThetaRange::Positive, ThetaRange::Symmetric] {
        let f = Formula {
            theta_range,
            ..Formula::parse(text, coords).unwrap()
        };
        check_conversion_in(&f, text, lo, size, &samples)?;
    }
    Ok(())
}

fn check_conversion_in(
    f: &Formula,
    text: &str,
    lo: [f64; 3],
    size: [f64; 3],
    samples: &[[f64; 3]],
) -> Result<(), TestCaseError> {
    let coords = f.coordinates;
    let boxed: [Interval; 3] = std::array::from_fn(|k| Interval::new(lo[k], lo[k] + size[k]));
    for t in samples {
        let p: [f64; 3] = std::array::from_fn(|k| lo[k] + size[k] * t[k]);
        let v = f.tape.eval(f.coordinates_of(p));
        if !v.is_finite() {
            continue;
        }
        // F - v is zero at p, so the box must not be ruled out.
        let shifted = Formula {
            theta_range: f.theta_range,
            ..Formula::parse(&format!("({text}) - ({v:?})"), coords).unwrap()
        };
        let mut slots: Vec<Split> = Vec::new();
        let test = test_box(&shifted, boxed, false, false, &mut slots);
        prop_assert!(
            test != BoxTest::Empty,
            "{text} = {v} at {p:?} in box {boxed:?} ({:?})",
            f.theta_range
        );
        let bounded = test_box(&shifted, boxed, false, true, &mut slots);
        prop_assert_eq!(bounded, BoxTest::MayContain, "{} on the axis", text);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    /// Boxes converted to spherical coordinates enclose the coordinates of their points.
    #[test]
    fn spherical_boxes_enclose_their_points(text in formula_over(&["r", "theta", "phi", "x", "y", "z"]), (lo, size, samples) in box_and_points()) {
        check_conversion(Coordinates::Spherical, &text, lo, size, samples)?;
    }

    /// Formulas G(θ, φ) - r, where r is compared with G as squares: as typed (r = G, and
    /// with -r) and under the paper's substitution (r = |G|), θ in either range.
    #[test]
    fn isolated_r_boxes_enclose_their_points(text in formula_over(&["theta", "phi"]), (lo, size, samples) in box_and_points(), negative in any::<bool>(), squared in any::<bool>(), positive in any::<bool>()) {
        let theta_range = if positive { ThetaRange::Positive } else { ThetaRange::Symmetric };
        let g = Formula { theta_range, ..Formula::parse(&text, Coordinates::Spherical).unwrap() };
        let boxed: [Interval; 3] = std::array::from_fn(|k| Interval::new(lo[k], lo[k] + size[k]));
        for t in samples {
            let p: [f64; 3] = std::array::from_fn(|k| lo[k] + size[k] * t[k]);
            let [r, theta, phi] = g.coordinates_of(p);
            let (r, theta, phi) = if negative && !squared { (-r, theta + std::f64::consts::PI, -phi) } else { (r, theta, phi) };
            let at = g.tape.eval([r, theta, phi]);
            // Typed: (G - v) - r is zero at p; squared: (G - v)² = r² with v = G - r·sign(G).
            let v = if squared { at - r * at.signum() } else { at - r };
            if !v.is_finite() {
                continue;
            }
            let shifted = Formula {
                theta_range,
                squared,
                ..Formula::parse(&format!("({text}) - ({v:?}) - r"), Coordinates::Spherical).unwrap()
            };
            prop_assert!(shifted.tape.isolated(0).is_some());
            let both = negative && !squared;
            let test = test_box(&shifted, boxed, both, true, &mut Vec::<Split>::new());
            prop_assert_eq!(test, BoxTest::MayContain, "{} at {:?}", text, p);
        }
    }

    /// The same for cylindrical coordinates.
    #[test]
    fn cylindrical_boxes_enclose_their_points(text in formula_over(&["r", "theta", "y", "x", "z", "phi"]), (lo, size, samples) in box_and_points()) {
        check_conversion(Coordinates::Cylindrical, &text, lo, size, samples)?;
    }
}

#[test]
fn boxes_across_the_cut_and_on_the_axis() {
    let formula = |text: &str, coordinates, theta_range| Formula {
        theta_range,
        ..Formula::parse(text, coordinates).unwrap()
    };
    let symmetric = |text: &str| formula(text, Coordinates::Cylindrical, ThetaRange::Symmetric);
    let positive = |text: &str| formula(text, Coordinates::Cylindrical, ThetaRange::Positive);
    let test = |f: &Formula, b: [Interval; 3], both_signs: bool, whole_axis: bool| {
        test_box(f, b, both_signs, whole_axis, &mut Vec::<Split>::new())
    };
    let i = |a: f64, b: f64| Interval::new(a, b);
    // (-π, π]: across the negative x axis, θ near +π on one side and -π on the other.
    let theta = symmetric("theta - 3.1");
    let across = [i(-1.0, -0.5), i(0.0, 1.0), i(-0.1, 0.1)];
    assert_eq!(test(&theta, across, false, false), BoxTest::MayContain);
    let minus = symmetric("theta + 3.1");
    assert_eq!(test(&minus, across, false, false), BoxTest::MayContain);
    // Away from the cut, θ near 0 only.
    let right = [i(0.5, 1.0), i(0.0, 1.0), i(-0.1, 0.1)];
    assert_eq!(test(&theta, right, false, false), BoxTest::Empty);
    // [0, 2π): the same boxes hold θ near π (no cut there), and θ near 0 or 2π across +x.
    assert_eq!(
        test(&positive("theta - 3.1"), across, false, false),
        BoxTest::MayContain
    );
    assert_eq!(
        test(&positive("theta + 3.1"), across, false, false),
        BoxTest::Empty
    );
    assert_eq!(
        test(&positive("theta - 0.05"), right, false, false),
        BoxTest::MayContain
    );
    assert_eq!(
        test(&positive("theta - 6.25"), right, false, false),
        BoxTest::MayContain
    );
    assert_eq!(
        test(&positive("theta - 3.1"), right, false, false),
        BoxTest::Empty
    );
    // On the axis θ is anything: undecided, or bounded by the whole turn.
    let axis = [i(-0.1, 0.1), i(0.0, 1.0), i(-0.1, 0.1)];
    assert_eq!(test(&theta, axis, false, false), BoxTest::Undecided);
    assert_eq!(test(&theta, axis, false, true), BoxTest::MayContain);
    assert_eq!(
        test(&positive("theta - 6"), axis, false, true),
        BoxTest::MayContain
    );
    assert_eq!(
        test(&symmetric("theta - 6"), axis, false, true),
        BoxTest::Empty
    );
    // Negative r: r + 0.5 = 0 has no point at r >= 0, but one at r = -0.5.
    let negative = formula("r + 0.5", Coordinates::Spherical, ThetaRange::Positive);
    let shell = [i(0.4, 0.6), i(-0.05, 0.05), i(-0.05, 0.05)];
    assert_eq!(test(&negative, shell, false, false), BoxTest::Empty);
    assert_eq!(test(&negative, shell, true, false), BoxTest::MayContain);
    // The paper's substitution: -0.5 - r = 0 squared is r = 0.5.
    let squared = Formula {
        squared: true,
        ..formula("-0.5 - r", Coordinates::Spherical, ThetaRange::Positive)
    };
    assert_eq!(test(&squared, shell, false, false), BoxTest::MayContain);
    let typed = formula("-0.5 - r", Coordinates::Spherical, ThetaRange::Positive);
    assert_eq!(test(&typed, shell, false, false), BoxTest::Empty);
}
