//! Forward-mode differentiation: a value with its partial derivatives with respect to the three
//! coordinate variables, for normals (the gradient of F).

use super::tape::Number;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dual {
    pub value: f64,
    pub grad: [f64; 3],
}

impl Dual {
    /// Coordinate variable `k` at `value` (derivative 1 along itself).
    pub fn variable(value: f64, k: usize) -> Self {
        let mut grad = [0.0; 3];
        grad[k] = 1.0;
        Dual { value, grad }
    }

    /// Chain rule: `f(self)` with `f'(self.value) = slope`.
    fn chain(self, value: f64, slope: f64) -> Self {
        Dual {
            value,
            grad: self.grad.map(|g| g * slope),
        }
    }

    fn combine(self, o: Self, value: f64, da: f64, db: f64) -> Self {
        Dual {
            value,
            grad: std::array::from_fn(|k| da * self.grad[k] + db * o.grad[k]),
        }
    }
}

impl Number for Dual {
    fn constant(c: f64) -> Self {
        Dual {
            value: c,
            grad: [0.0; 3],
        }
    }
    fn neg(self) -> Self {
        self.chain(-self.value, -1.0)
    }
    fn add(self, o: Self) -> Self {
        self.combine(o, self.value + o.value, 1.0, 1.0)
    }
    fn sub(self, o: Self) -> Self {
        self.combine(o, self.value - o.value, 1.0, -1.0)
    }
    fn mul(self, o: Self) -> Self {
        self.combine(o, self.value * o.value, o.value, self.value)
    }
    fn div(self, o: Self) -> Self {
        let q = self.value / o.value;
        self.combine(o, q, 1.0 / o.value, -q / o.value)
    }
    fn powi(self, n: i32) -> Self {
        let slope = if n == 0 {
            0.0
        } else {
            n as f64 * self.value.powi(n - 1)
        };
        self.chain(Number::powi(self.value, n), slope)
    }
    fn sqrt(self) -> Self {
        let r = self.value.sqrt();
        self.chain(r, 0.5 / r)
    }
    fn abs(self) -> Self {
        self.chain(self.value.abs(), if self.value < 0.0 { -1.0 } else { 1.0 })
    }
    fn sin(self) -> Self {
        self.chain(self.value.sin(), self.value.cos())
    }
    fn cos(self) -> Self {
        self.chain(self.value.cos(), -self.value.sin())
    }
    fn tan(self) -> Self {
        let t = self.value.tan();
        self.chain(t, 1.0 + t * t)
    }
    fn exp(self) -> Self {
        let e = self.value.exp();
        self.chain(e, e)
    }
    fn ln(self) -> Self {
        self.chain(self.value.ln(), 1.0 / self.value)
    }
    fn atan2(self, x: Self) -> Self {
        let (y, xv) = (self.value, x.value);
        let r2 = y * y + xv * xv;
        self.combine(x, y.atan2(xv), xv / r2, -y / r2)
    }
    fn min(self, o: Self) -> Self {
        if self.value.is_nan() || (!o.value.is_nan() && self.value <= o.value) {
            self
        } else {
            o
        }
    }
    fn max(self, o: Self) -> Self {
        if self.value.is_nan() || (!o.value.is_nan() && self.value >= o.value) {
            self
        } else {
            o
        }
    }
}
