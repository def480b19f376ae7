//! Implicit surfaces typed as formulas (Stolte & Kaufman): a small language compiled to a
//! tape, evaluated at points, over interval boxes with a guaranteed enclosure, and with its
//! gradient, in Cartesian, spherical or cylindrical coordinates.

mod coordinates;
mod dual;
pub mod examples;
pub mod formula_solid;
mod interval;
mod parse;
pub mod reference;
mod split;
mod tape;

pub use coordinates::{BoxTest, test_box, to_coordinates, value_at};
pub use dual::Dual;
pub use interval::Interval;
pub use split::{Enclosure, Split};
pub use tape::{Instr, Number, Tape};

use crate::error::Result;

/// The coordinate system a formula is written in. Spherical follows the paper: theta is
/// measured in the XZ plane from the X axis, phi from the XZ plane, so
/// `(x, y, z) = (r cos(theta) cos(phi), r sin(phi), r sin(theta) cos(phi))`; cylindrical
/// uses r and theta in the XZ plane and y along the axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coordinates {
    Cartesian,
    Spherical,
    Cylindrical,
}

impl Coordinates {
    /// The variable names, in tape slot order.
    pub fn variables(self) -> [&'static str; 3] {
        match self {
            Coordinates::Cartesian => ["x", "y", "z"],
            Coordinates::Spherical => ["r", "theta", "phi"],
            Coordinates::Cylindrical => ["r", "theta", "y"],
        }
    }
}

crate::named_choices! {
    Coordinates, "the coordinates":
    "cartesian" => Cartesian,
    "spherical" => Spherical,
    "cylindrical" => Cylindrical,
}

/// The values θ takes: the paper's `[0, 2π)`, measured from +x toward +z with its cut along
/// the positive x axis, or `(-π, π]`, cut along the negative x axis (`atan2`'s).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ThetaRange {
    #[default]
    Positive,
    Symmetric,
}

crate::named_choices! {
    ThetaRange, "the theta range":
    "positive" => Positive,
    "symmetric" => Symmetric,
}

/// A compiled formula F; the surface is F = 0.
#[derive(Clone, Debug, PartialEq)]
pub struct Formula {
    pub text: String,
    pub coordinates: Coordinates,
    pub tape: Tape,
    /// Where θ lies (spherical and cylindrical coordinates).
    pub theta_range: ThetaRange,
    /// Stolte & Kaufman's substitution for F = G - r: the surface [G]² - r² = 0, that is
    /// r = |G|, instead of r = G (G >= 0) as typed.
    pub squared: bool,
}

impl Formula {
    /// Parses `text` (θ in the paper's [0, 2π), r as typed); errors point at the column.
    pub fn parse(text: &str, coordinates: Coordinates) -> Result<Formula> {
        Formula::parse_in(text, coordinates, ThetaRange::default())
    }

    /// Parses `text` with θ in `theta_range` (which blended θ in a Cartesian formula follows).
    pub fn parse_in(
        text: &str,
        coordinates: Coordinates,
        theta_range: ThetaRange,
    ) -> Result<Formula> {
        Ok(Formula {
            text: text.to_string(),
            coordinates,
            tape: parse::parse(text, coordinates, theta_range)?,
            theta_range,
            squared: false,
        })
    }

    /// The coordinates of a Cartesian point (or box, or dual number) in this formula's
    /// system and θ range.
    pub fn coordinates_of<N: Number>(&self, p: [N; 3]) -> [N; 3] {
        to_coordinates(self.coordinates, self.theta_range, p)
    }

    /// The Cartesian gradient of F at the world point `p`; `slots` is scratch space.
    pub fn gradient_at(&self, p: [f64; 3], slots: &mut Vec<Dual>) -> glam::DVec3 {
        self.value_and_gradient_at(p, slots).1
    }

    /// F over the length of its gradient at the world point `p`, the distance to F = 0 to
    /// first order (its sign F's), and the unit gradient (zero where F has none); `slots` is
    /// scratch space.
    pub fn first_order_distance(&self, p: [f64; 3], slots: &mut Vec<Dual>) -> (f64, glam::DVec3) {
        let (f, g) = self.value_and_gradient_at(p, slots);
        let length = g.length();
        if length > 0.0 && length.is_finite() {
            (f / length, g / length)
        } else {
            (f, glam::DVec3::ZERO)
        }
    }

    /// F and its Cartesian gradient at the world point `p`; `slots` is scratch space.
    pub fn value_and_gradient_at(&self, p: [f64; 3], slots: &mut Vec<Dual>) -> (f64, glam::DVec3) {
        let vars: [Dual; 3] = std::array::from_fn(|a| Dual::variable(p[a], a));
        let d = self.tape.eval_with(self.coordinates_of(vars), slots);
        (d.value, glam::DVec3::from_array(d.grad))
    }
}
