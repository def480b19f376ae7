//! A compiled formula: a flat list of instructions, each reading earlier slots, evaluated
//! the same way over any number type — plain `f64` at a point, `Interval` over a box, `Dual`
//! for the gradient.

/// One instruction; operands are indices of earlier instructions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Instr {
    Const(f64),
    /// Coordinate variable 0, 1 or 2 (x y z, r theta phi, or r theta y).
    Var(u8),
    Neg(u32),
    Add(u32, u32),
    Sub(u32, u32),
    Mul(u32, u32),
    Div(u32, u32),
    /// Integer power.
    Pow(u32, i32),
    Sqrt(u32),
    Abs(u32),
    Sin(u32),
    Cos(u32),
    Tan(u32),
    Exp(u32),
    Log(u32),
    /// atan2(y, x).
    Atan2(u32, u32),
    Min(u32, u32),
    Max(u32, u32),
}

/// What a number type must provide to run a tape.
pub trait Number: Copy {
    fn constant(c: f64) -> Self;
    fn neg(self) -> Self;
    fn add(self, o: Self) -> Self;
    fn sub(self, o: Self) -> Self;
    fn mul(self, o: Self) -> Self;
    fn div(self, o: Self) -> Self;
    fn powi(self, n: i32) -> Self;
    fn sqrt(self) -> Self;
    fn abs(self) -> Self;
    fn sin(self) -> Self;
    fn cos(self) -> Self;
    fn tan(self) -> Self;
    fn exp(self) -> Self;
    fn ln(self) -> Self;
    fn atan2(self, x: Self) -> Self;
    fn min(self, o: Self) -> Self;
    fn max(self, o: Self) -> Self;
}

#[derive(Clone, Debug, PartialEq)]
pub struct Tape {
    pub(crate) instrs: Vec<Instr>,
}

impl Tape {
    pub fn len(&self) -> usize {
        self.instrs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.instrs.is_empty()
    }

    /// Whether the formula divides (a quotient or a negative power): only then can an
    /// interval result have a gap at a pole.
    pub fn divides(&self) -> bool {
        self.instrs
            .iter()
            .any(|i| matches!(i, Instr::Div(..)) || matches!(i, Instr::Pow(_, n) if *n < 0))
    }

    /// When the formula is `G - v` with variable `k` (v) appearing nowhere else, the slot of
    /// G: then F = 0 is `G = v`, and G's interval can be compared with v's directly.
    pub fn isolated(&self, k: u8) -> Option<u32> {
        let uses = self.instrs.iter().filter(|&&i| i == Instr::Var(k)).count();
        match self.instrs.last() {
            Some(&Instr::Sub(g, v)) if uses == 1 && self.instrs[v as usize] == Instr::Var(k) => {
                Some(g)
            }
            _ => None,
        }
    }

    /// Runs the tape with the three coordinate variables; `slots` is scratch space kept
    /// between calls to avoid allocating. The value of the last instruction is returned.
    pub fn eval_with<N: Number>(&self, vars: [N; 3], slots: &mut Vec<N>) -> N {
        slots.clear();
        for &ins in &self.instrs {
            let s = |i: u32| slots[i as usize];
            let v = match ins {
                Instr::Const(c) => N::constant(c),
                Instr::Var(k) => vars[k as usize],
                Instr::Neg(a) => s(a).neg(),
                Instr::Add(a, b) => s(a).add(s(b)),
                Instr::Sub(a, b) => s(a).sub(s(b)),
                Instr::Mul(a, b) => s(a).mul(s(b)),
                Instr::Div(a, b) => s(a).div(s(b)),
                Instr::Pow(a, n) => s(a).powi(n),
                Instr::Sqrt(a) => s(a).sqrt(),
                Instr::Abs(a) => s(a).abs(),
                Instr::Sin(a) => s(a).sin(),
                Instr::Cos(a) => s(a).cos(),
                Instr::Tan(a) => s(a).tan(),
                Instr::Exp(a) => s(a).exp(),
                Instr::Log(a) => s(a).ln(),
                Instr::Atan2(a, b) => s(a).atan2(s(b)),
                Instr::Min(a, b) => s(a).min(s(b)),
                Instr::Max(a, b) => s(a).max(s(b)),
            };
            slots.push(v);
        }
        *slots.last().expect("a compiled formula has an instruction")
    }

    /// `eval_with` with fresh scratch space.
    pub fn eval<N: Number>(&self, vars: [N; 3]) -> N {
        self.eval_with(vars, &mut Vec::with_capacity(self.instrs.len()))
    }
}

impl Number for f64 {
    fn constant(c: f64) -> Self {
        c
    }
    fn neg(self) -> Self {
        -self
    }
    fn add(self, o: Self) -> Self {
        self + o
    }
    fn sub(self, o: Self) -> Self {
        self - o
    }
    fn mul(self, o: Self) -> Self {
        self * o
    }
    fn div(self, o: Self) -> Self {
        self / o
    }
    fn powi(self, n: i32) -> Self {
        // IEEE gives NaN^0 = 1; here an undefined base stays undefined.
        if self.is_nan() {
            f64::NAN
        } else {
            f64::powi(self, n)
        }
    }
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    fn abs(self) -> Self {
        f64::abs(self)
    }
    fn sin(self) -> Self {
        f64::sin(self)
    }
    fn cos(self) -> Self {
        f64::cos(self)
    }
    fn tan(self) -> Self {
        f64::tan(self)
    }
    fn exp(self) -> Self {
        f64::exp(self)
    }
    fn ln(self) -> Self {
        f64::ln(self)
    }
    fn atan2(self, x: Self) -> Self {
        f64::atan2(self, x)
    }
    // Undefined (NaN) propagates through min and max as through everything else, as it does
    // for intervals: a formula is undefined wherever a part of it is.
    fn min(self, o: Self) -> Self {
        if self.is_nan() || o.is_nan() {
            f64::NAN
        } else {
            f64::min(self, o)
        }
    }
    fn max(self, o: Self) -> Self {
        if self.is_nan() || o.is_nan() {
            f64::NAN
        } else {
            f64::max(self, o)
        }
    }
}
