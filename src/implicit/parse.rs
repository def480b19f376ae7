//! The formula language, parsed straight into a tape.
//!
//! ```text
//! formula  := (name '=' expr ';')* expr ';'?
//! expr     := term (('+' | '-') term)*
//! term     := unary (('*' | '/') unary)*
//! unary    := ('-' | '+') unary | power
//! power    := atom ('^' integer)?          integer: optionally signed, or in parentheses
//! atom     := number | 'pi' | variable | name | function '(' expr (',' expr)* ')' | '(' expr ')'
//! ```
//!
//! Functions: sqrt abs sin cos tan exp log (one argument), atan2 min max (two). `-x^2` is
//! `-(x^2)`. Named sub-expressions are computed once and may be used by later lines.
//!
//! Coordinates blend, as Stolte & Kaufman's formulas do: besides its own three variables a
//! formula may use the other systems' (`x y z` in a spherical or cylindrical formula, `r theta
//! phi` in a Cartesian one), each computed once from its own where first used:
//! x = r cos φ cos θ, y = r sin φ, z = r cos φ sin θ (cylindrical: x = r cos θ, z = r sin θ);
//! r = √(x² + y² + z²), θ in the formula's range, φ = atan2(y, √(x² + z²)) (cylindrical:
//! atan2(y, r)). The same point has the same blended coordinates whichever sign of r
//! describes it. A named sub-expression may take such a name for itself.

use super::tape::{Instr, Tape};
use super::{Coordinates, ThetaRange};
use crate::error::{Error, Result};

#[derive(Clone, Debug, PartialEq)]
enum Token {
    Number(f64),
    Ident(String),
    Op(char),
}

struct Parser<'a> {
    text: &'a str,
    tokens: Vec<(Token, usize)>,
    at: usize,
    variables: [&'a str; 3],
    coordinates: Coordinates,
    theta_range: ThetaRange,
    names: Vec<(String, u32)>,
    instrs: Vec<Instr>,
    /// Nesting of signs, parentheses and function calls: bounded, so that no input can
    /// exhaust the stack (the evaluation runs a flat tape and does not recurse).
    depth: usize,
}

/// Deepest nesting a formula may have.
const MAX_DEPTH: usize = 100;

/// Compiles `text` over the variables of `coordinates` (in slot order), θ in `theta_range`.
pub fn parse(text: &str, coordinates: Coordinates, theta_range: ThetaRange) -> Result<Tape> {
    let mut p = Parser {
        text,
        tokens: tokenize(text)?,
        at: 0,
        variables: coordinates.variables(),
        coordinates,
        theta_range,
        names: Vec::new(),
        instrs: Vec::new(),
        depth: 0,
    };
    let root = p.formula()?;
    // The value is the last instruction: make sure the root is last.
    if root as usize + 1 != p.instrs.len() {
        let zero = p.push(Instr::Const(0.0));
        p.push(Instr::Add(root, zero));
    }
    Ok(Tape { instrs: p.instrs })
}

fn error(text: &str, column: usize, message: impl Into<String>) -> Error {
    Error::Formula {
        text: text.to_string(),
        column,
        message: message.into(),
    }
}

fn tokenize(text: &str) -> Result<Vec<(Token, usize)>> {
    let chars: Vec<char> = text.chars().collect();
    let mut tokens = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let column = i + 1;
        if c.is_whitespace() {
            i += 1;
        } else if c.is_ascii_digit() || c == '.' {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
                i += 1;
            }
            // An exponent: 1e-3, 2.5E6.
            if i < chars.len() && (chars[i] == 'e' || chars[i] == 'E') {
                let mut j = i + 1;
                if j < chars.len() && (chars[j] == '+' || chars[j] == '-') {
                    j += 1;
                }
                if j < chars.len() && chars[j].is_ascii_digit() {
                    i = j;
                    while i < chars.len() && chars[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let word: String = chars[start..i].iter().collect();
            let value = word
                .parse::<f64>()
                .map_err(|_| error(text, column, format!("`{word}` is not a number")))?;
            if !value.is_finite() {
                return Err(error(
                    text,
                    column,
                    format!("`{word}` is too large for a double-precision number"),
                ));
            }
            tokens.push((Token::Number(value), column));
        } else if c.is_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            tokens.push((Token::Ident(chars[start..i].iter().collect()), column));
        } else if "+-*/^(),;=".contains(c) {
            tokens.push((Token::Op(c), column));
            i += 1;
        } else {
            return Err(error(text, column, format!("unexpected character `{c}`")));
        }
    }
    Ok(tokens)
}

type UnaryMaker = fn(u32) -> Instr;
type BinaryMaker = fn(u32, u32) -> Instr;

const UNARY: [(&str, UnaryMaker); 7] = [
    ("sqrt", Instr::Sqrt),
    ("abs", Instr::Abs),
    ("sin", Instr::Sin),
    ("cos", Instr::Cos),
    ("tan", Instr::Tan),
    ("exp", Instr::Exp),
    ("log", Instr::Log),
];
const BINARY: [(&str, BinaryMaker); 3] = [
    ("atan2", Instr::Atan2),
    ("min", Instr::Min),
    ("max", Instr::Max),
];

impl Parser<'_> {
    fn push(&mut self, ins: Instr) -> u32 {
        self.instrs.push(ins);
        self.instrs.len() as u32 - 1
    }

    fn peek(&self) -> Option<&Token> {
        self.tokens.get(self.at).map(|(t, _)| t)
    }

    /// Column of the current token, or one past the end.
    fn column(&self) -> usize {
        self.tokens
            .get(self.at)
            .map(|&(_, c)| c)
            .unwrap_or(self.text.chars().count() + 1)
    }

    fn fail<T>(&self, message: impl Into<String>) -> Result<T> {
        Err(error(self.text, self.column(), message))
    }

    fn eat(&mut self, op: char) -> bool {
        if self.peek() == Some(&Token::Op(op)) {
            self.at += 1;
            true
        } else {
            false
        }
    }

    fn expect(&mut self, op: char) -> Result<()> {
        if self.eat(op) {
            Ok(())
        } else {
            self.fail(format!("expected `{op}`"))
        }
    }

    fn formula(&mut self) -> Result<u32> {
        if self.tokens.is_empty() {
            return self.fail("the formula is empty");
        }
        loop {
            // `name = expr;` defines a sub-expression.
            if let (Some(Token::Ident(name)), Some((Token::Op('='), _))) =
                (self.peek().cloned(), self.tokens.get(self.at + 1))
            {
                let column = self.column();
                if self.is_reserved(&name) {
                    return Err(error(
                        self.text,
                        column,
                        format!("`{name}` is a variable or function and cannot be redefined"),
                    ));
                }
                self.at += 2;
                let slot = self.expr()?;
                self.expect(';')?;
                self.names.retain(|(n, _)| *n != name);
                self.names.push((name, slot));
                continue;
            }
            let root = self.expr()?;
            self.eat(';');
            if self.at < self.tokens.len() {
                return self.fail("unexpected text after the formula");
            }
            return Ok(root);
        }
    }

    fn is_reserved(&self, name: &str) -> bool {
        name == "pi"
            || self.variables.contains(&name)
            || UNARY.iter().any(|(n, _)| *n == name)
            || BINARY.iter().any(|(n, _)| *n == name)
    }

    fn expr(&mut self) -> Result<u32> {
        let mut left = self.term()?;
        loop {
            if self.eat('+') {
                let right = self.term()?;
                left = self.push(Instr::Add(left, right));
            } else if self.eat('-') {
                let right = self.term()?;
                left = self.push(Instr::Sub(left, right));
            } else {
                return Ok(left);
            }
        }
    }

    fn term(&mut self) -> Result<u32> {
        let mut left = self.unary()?;
        loop {
            if self.eat('*') {
                let right = self.unary()?;
                left = self.push(Instr::Mul(left, right));
            } else if self.eat('/') {
                let right = self.unary()?;
                left = self.push(Instr::Div(left, right));
            } else {
                return Ok(left);
            }
        }
    }

    fn unary(&mut self) -> Result<u32> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return self.fail(format!(
                "the formula nests more than {MAX_DEPTH} levels deep (signs, parentheses, functions)"
            ));
        }
        let value = if self.eat('-') {
            self.unary().map(|a| self.push(Instr::Neg(a)))
        } else if self.eat('+') {
            self.unary()
        } else {
            self.power()
        };
        self.depth -= 1;
        value
    }

    fn power(&mut self) -> Result<u32> {
        let base = self.atom()?;
        if !self.eat('^') {
            return Ok(base);
        }
        let column = self.column();
        let parenthesized = self.eat('(');
        let negative = self.eat('-');
        let n = match self.peek() {
            Some(&Token::Number(v)) if v.fract() == 0.0 && v.abs() <= 1024.0 => {
                self.at += 1;
                v as i32
            }
            Some(&Token::Op(op)) => {
                let at = self.column();
                return Err(error(
                    self.text,
                    at,
                    format!(
                        "a stray `{op}` where the power after `^` should be: write an integer \
                         from -1024 to 1024, as in y^2"
                    ),
                ));
            }
            _ => {
                return Err(error(
                    self.text,
                    column,
                    "only integer powers are supported (an integer from -1024 to 1024 after `^`)",
                ));
            }
        };
        if parenthesized {
            self.expect(')')?;
        }
        Ok(self.push(Instr::Pow(base, if negative { -n } else { n })))
    }

    fn atom(&mut self) -> Result<u32> {
        let column = self.column();
        let Some(token) = self.peek().cloned() else {
            return self.fail("the formula ends too early");
        };
        self.at += 1;
        match token {
            Token::Number(v) => Ok(self.push(Instr::Const(v))),
            Token::Op('(') => {
                let inner = self.expr()?;
                self.expect(')')?;
                Ok(inner)
            }
            Token::Op(c) => Err(error(self.text, column, format!("unexpected `{c}`"))),
            Token::Ident(name) => self.name(&name, column),
        }
    }

    fn name(&mut self, name: &str, column: usize) -> Result<u32> {
        if name == "pi" {
            return Ok(self.push(Instr::Const(std::f64::consts::PI)));
        }
        if let Some(k) = self.variables.iter().position(|v| *v == name) {
            return Ok(self.push(Instr::Var(k as u8)));
        }
        if let Some(&(_, slot)) = self.names.iter().rev().find(|(n, _)| n == name) {
            return Ok(slot);
        }
        if let Some(slot) = self.blended(name) {
            // Computed once: later uses find it among the names.
            self.names.insert(0, (name.to_string(), slot));
            return Ok(slot);
        }
        if let Some(&(_, make)) = UNARY.iter().find(|(n, _)| *n == name) {
            let args = self.arguments(name, 1)?;
            return Ok(self.push(make(args[0])));
        }
        if let Some(&(_, make)) = BINARY.iter().find(|(n, _)| *n == name) {
            let args = self.arguments(name, 2)?;
            return Ok(self.push(make(args[0], args[1])));
        }
        Err(error(
            self.text,
            column,
            format!(
                "unknown name `{name}` (variables: x y z r theta phi; functions: sqrt abs sin cos tan exp log atan2 min max)"
            ),
        ))
    }

    /// Another system's coordinate, computed from this formula's own variables (see the
    /// module docs); `None` when `name` is none.
    fn blended(&mut self, name: &str) -> Option<u32> {
        use Instr::*;
        let var = |p: &mut Self, k: u8| p.push(Var(k));
        let slot = match (self.coordinates, name) {
            (Coordinates::Cartesian, "r") => {
                let (x, y, z) = (var(self, 0), var(self, 1), var(self, 2));
                let (x2, y2, z2) = (
                    self.push(Pow(x, 2)),
                    self.push(Pow(y, 2)),
                    self.push(Pow(z, 2)),
                );
                let xy = self.push(Add(x2, y2));
                let all = self.push(Add(xy, z2));
                self.push(Sqrt(all))
            }
            (Coordinates::Cartesian, "theta") => {
                let (x, z) = (var(self, 0), var(self, 2));
                match self.theta_range {
                    ThetaRange::Symmetric => self.push(Atan2(z, x)),
                    ThetaRange::Positive => {
                        let minus_x = self.push(Neg(x));
                        let turned = self.push(Atan2(z, minus_x));
                        let pi = self.push(Const(std::f64::consts::PI));
                        self.push(Sub(pi, turned))
                    }
                }
            }
            (Coordinates::Cartesian, "phi") => {
                let (x, y, z) = (var(self, 0), var(self, 1), var(self, 2));
                let (x2, z2) = (self.push(Pow(x, 2)), self.push(Pow(z, 2)));
                let sum = self.push(Add(x2, z2));
                let horizontal = self.push(Sqrt(sum));
                self.push(Atan2(y, horizontal))
            }
            (Coordinates::Spherical, "x" | "y" | "z") => {
                let (r, theta, phi) = (var(self, 0), var(self, 1), var(self, 2));
                if name == "y" {
                    let sin_phi = self.push(Sin(phi));
                    self.push(Mul(r, sin_phi))
                } else {
                    let cos_phi = self.push(Cos(phi));
                    let horizontal = self.push(Mul(r, cos_phi));
                    let angle = self.push(if name == "x" { Cos(theta) } else { Sin(theta) });
                    self.push(Mul(horizontal, angle))
                }
            }
            (Coordinates::Cylindrical, "x" | "z") => {
                let (r, theta) = (var(self, 0), var(self, 1));
                let angle = self.push(if name == "x" { Cos(theta) } else { Sin(theta) });
                self.push(Mul(r, angle))
            }
            (Coordinates::Cylindrical, "phi") => {
                let (r, y) = (var(self, 0), var(self, 2));
                self.push(Atan2(y, r))
            }
            _ => return None,
        };
        Some(slot)
    }

    fn arguments(&mut self, function: &str, count: usize) -> Result<Vec<u32>> {
        if !self.eat('(') {
            return self.fail(format!("`{function}` needs its arguments in parentheses"));
        }
        let mut args = vec![self.expr()?];
        while self.eat(',') {
            args.push(self.expr()?);
        }
        self.expect(')')?;
        if args.len() != count {
            return self.fail(format!(
                "`{function}` takes {count} argument{}, not {}",
                if count == 1 { "" } else { "s" },
                args.len()
            ));
        }
        Ok(args)
    }
}
