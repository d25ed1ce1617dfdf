//! User-supplied expressions: integrands and densities in the variables of a box domain.
//!
//! Parsing and evaluation are done by `exmex`; this module binds the expression's variable
//! names to the dimensions of the domain and checks everything a user can get wrong.

use anyhow::{anyhow, bail, Context, Result};
use exmex::{Express, FlatEx};

/// Most dimensions an integration domain may have.
pub const MAX_DIMS: usize = 32;

/// The names of the first dimensions, after which only `x1..xd` work.
const SHORT_NAMES: [&str; 4] = ["x", "y", "z", "w"];

/// An expression of the domain's coordinates.
#[derive(Clone, Debug)]
pub struct Expression {
    text: String,
    expr: FlatEx<f64>,
    /// For each of the expression's variables (in exmex's order), the dimension it reads.
    var_dims: Vec<usize>,
}

/// The variable names available for a domain of `dims` dimensions, for messages.
pub fn variable_names(dims: usize) -> String {
    let long: Vec<String> = (1..=dims).map(|i| format!("x{i}")).collect();
    if dims <= SHORT_NAMES.len() {
        format!(
            "{} (or {})",
            SHORT_NAMES[..dims].join(", "),
            long.join(", ")
        )
    } else {
        long.join(", ")
    }
}

fn dimension_of(name: &str, dims: usize) -> Option<usize> {
    if let Some(i) = SHORT_NAMES.iter().position(|&s| s == name) {
        return (i < dims).then_some(i);
    }
    let index: usize = name.strip_prefix('x')?.parse().ok()?;
    (1..=dims).contains(&index).then(|| index - 1)
}

/// Rewrites what exmex does not read itself: the word `pi` becomes its constant `PI`, and
/// numbers in scientific notation (`2.5e-3`) are written out in positional notation.
/// The functions expressions may call (exmex's for `f64`).
const FUNCTIONS: [&str; 28] = [
    "abs", "signum", "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "asinh",
    "acosh", "atanh", "floor", "round", "ceil", "trunc", "fract", "exp", "sqrt", "cbrt", "ln",
    "log2", "log10", "log", "min", "max",
];

/// Every name called as a function, `name(`, is one of [`FUNCTIONS`] (the parser's own message
/// for an unknown one is about parentheses).
fn check_functions(text: &str) -> Result<()> {
    let chars: Vec<char> = text.chars().collect();
    let is_word = |c: char| c.is_alphanumeric() || c == '_';
    let mut i = 0;
    while i < chars.len() {
        if chars[i].is_alphabetic() && (i == 0 || !is_word(chars[i - 1])) {
            let start = i;
            while i < chars.len() && is_word(chars[i]) {
                i += 1;
            }
            let name: String = chars[start..i].iter().collect();
            let mut j = i;
            while j < chars.len() && chars[j].is_whitespace() {
                j += 1;
            }
            if chars.get(j) == Some(&'(') && !FUNCTIONS.contains(&name.as_str()) {
                bail!(
                    "unknown function '{name}' (the functions are {})",
                    FUNCTIONS.join(", ")
                );
            }
        } else {
            i += 1;
        }
    }
    Ok(())
}

fn normalise(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let chars: Vec<char> = text.chars().collect();
    let is_word = |c: char| c.is_alphanumeric() || c == '_';
    let mut i = 0;
    while i < chars.len() {
        let starts_word = i == 0 || !is_word(chars[i - 1]);
        if starts_word
            && chars[i] == 'p'
            && chars.get(i + 1) == Some(&'i')
            && !chars.get(i + 2).is_some_and(|&c| is_word(c))
        {
            out.push_str("PI");
            i += 2;
        } else if starts_word && (chars[i].is_ascii_digit() || chars[i] == '.') {
            let end = number_end(&chars, i);
            let literal: String = chars[i..end].iter().collect();
            match literal.parse::<f64>() {
                Ok(v) if literal.contains(['e', 'E']) => out.push_str(&format!("{v}")),
                _ => out.push_str(&literal),
            }
            i = end;
        } else {
            out.push(chars[i]);
            i += 1;
        }
    }
    out
}

/// The index just past the number literal starting at `i` (digits, a point, and an optional
/// exponent such as `e-3`).
fn number_end(chars: &[char], mut i: usize) -> usize {
    while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
        i += 1;
    }
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
    i
}

/// The lexical pieces of an expression, just enough to spot ambiguous notation.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Token {
    Operand,
    Open,
    Close,
    Comma,
    Op(char),
}

fn tokens(text: &str) -> Vec<Token> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() {
            i += 1;
        } else if c.is_ascii_digit() || c == '.' {
            i = number_end(&chars, i);
            out.push(Token::Operand);
        } else if c.is_alphabetic() || c == '_' {
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            out.push(Token::Operand);
        } else if c == '{' {
            while i < chars.len() && chars[i] != '}' {
                i += 1;
            }
            i += 1;
            out.push(Token::Operand);
        } else {
            out.push(match c {
                '(' => Token::Open,
                ')' => Token::Close,
                ',' => Token::Comma,
                _ => Token::Op(c),
            });
            i += 1;
        }
    }
    out
}

/// The index just past the operand starting at `i` (a number, a name, a call `f(...)` or a
/// bracketed group, after any unary signs).
fn operand_end(t: &[Token], mut i: usize) -> usize {
    while matches!(t.get(i), Some(Token::Op('-' | '+'))) {
        i += 1;
    }
    if t.get(i) == Some(&Token::Operand) {
        i += 1;
    }
    if t.get(i) == Some(&Token::Open) {
        let mut depth = 0usize;
        while i < t.len() {
            match t[i] {
                Token::Open => depth += 1,
                Token::Close => {
                    depth = depth.saturating_sub(1);
                    if depth == 0 {
                        return i + 1;
                    }
                }
                _ => {}
            }
            i += 1;
        }
    }
    i
}

/// Rejects notation that mathematicians and expression parsers read differently: a leading
/// minus on a power (`-x^2`: the parser would take `(-x)^2`, mathematics `-(x^2)`) and chained
/// powers (`a^b^c`: the parser would take `(a^b)^c`, mathematics `a^(b^c)`).
fn check_ambiguity(text: &str) -> Result<()> {
    let t = tokens(text);
    for i in 0..t.len() {
        let unary = matches!(t[i], Token::Op('-'))
            && (i == 0 || matches!(t[i - 1], Token::Open | Token::Comma | Token::Op(_)));
        if unary && t.get(operand_end(&t, i + 1)) == Some(&Token::Op('^')) {
            bail!(
                "ambiguous minus sign before a power in \"{text}\": write -(x^2) for the \
                 negated power or (-x)^2 for the power of the negative"
            );
        }
        if t[i] == Token::Op('^') && t.get(operand_end(&t, i + 1)) == Some(&Token::Op('^')) {
            bail!("ambiguous chained power in \"{text}\": write a^(b^c) or (a^b)^c");
        }
    }
    Ok(())
}

impl Expression {
    /// Parses `text` as a function of the coordinates of a `dims`-dimensional domain.
    pub fn parse(text: &str, dims: usize, what: &str) -> Result<Self> {
        if text.trim().is_empty() {
            bail!("{what} is empty: expected an expression such as \"x*x + y\"");
        }
        check_ambiguity(text).with_context(|| format!("cannot use {what}"))?;
        check_functions(text).with_context(|| format!("cannot use {what} \"{text}\""))?;
        let expr = exmex::parse::<f64>(&normalise(text))
            .map_err(|e| anyhow!("cannot parse {what} \"{text}\": {}", clean_message(e.msg())))?;
        let var_dims = expr
            .var_names()
            .iter()
            .map(|name| {
                dimension_of(name, dims).ok_or_else(|| {
                    anyhow!(
                        "unknown variable '{name}' in {what} \"{text}\": with {dims} domain{} \
                         the variables are {}",
                        if dims == 1 { "" } else { "s" },
                        variable_names(dims)
                    )
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Expression {
            text: text.to_string(),
            expr,
            var_dims,
        })
    }

    /// The text as the user wrote it.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The value at the point `x` (one coordinate per dimension). Non-finite results are
    /// returned as they are; evaluation itself cannot fail once parsing succeeded.
    #[inline]
    pub fn eval(&self, x: &[f64]) -> f64 {
        let mut vals = [0.0f64; MAX_DIMS];
        for (v, &d) in vals.iter_mut().zip(&self.var_dims) {
            *v = x[d];
        }
        self.expr
            .eval(&vals[..self.var_dims.len()])
            .unwrap_or(f64::NAN)
    }
}

/// The parser's message without the internal structures it sometimes appends.
fn clean_message(msg: &str) -> &str {
    let end = msg
        .find(" Operator {")
        .or_else(|| msg.find("Operator {"))
        .unwrap_or(msg.len());
    msg[..end].trim_end_matches([',', ' '])
}

/// Reads one bound of a domain: a number or a constant expression such as `-pi/2`.
pub fn parse_constant(text: &str) -> Result<f64> {
    let t = text.trim();
    if let Ok(v) = t.parse::<f64>() {
        return Ok(v);
    }
    exmex::eval_str::<f64>(&normalise(t))
        .map_err(|e| anyhow!("{}", clean_message(e.msg())))
        .with_context(|| format!("'{t}' is not a number"))
}

/// Reads an interval `a,b` whose bounds are numbers or constant expressions, finite, with
/// a < b; an error names the setting (`--domain -2,2`).
pub fn parse_interval(name: &str, text: &str) -> Result<(f64, f64)> {
    let Some((a, b)) = text.split_once(',').filter(|(_, b)| !b.contains(',')) else {
        bail!("{name} {text}: expected two bounds a,b such as -2,2");
    };
    let a = parse_constant(a).with_context(|| format!("{name} {text}"))?;
    let b = parse_constant(b).with_context(|| format!("{name} {text}"))?;
    if !(a.is_finite() && b.is_finite()) {
        bail!("{name} {text}: bounds must be finite");
    }
    if a >= b {
        bail!("{name} {text}: the interval is empty (need a < b)");
    }
    Ok((a, b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn intervals_take_constant_bounds_in_order() {
        let (a, b) = parse_interval("--domain", "-pi/2, 1").unwrap();
        assert_eq!((a, b), (-std::f64::consts::FRAC_PI_2, 1.0));
        for (text, expected) in [
            ("0", "two bounds"),
            ("0,1,2", "two bounds"),
            ("1,1", "empty"),
            ("0,q", "'q' is not a number"),
            ("0,1/0", "finite"),
        ] {
            let e = format!("{:#}", parse_interval("--domain", text).unwrap_err());
            assert!(e.starts_with(&format!("--domain {text}")), "{e}");
            assert!(e.contains(expected), "{text}: {e}");
        }
    }

    #[test]
    fn binds_variables_to_dimensions() {
        let e = Expression::parse("y - 2*x + x2", 2, "integrand").unwrap();
        assert_eq!(e.eval(&[1.0, 10.0]), 10.0 - 2.0 + 10.0);
        let e = Expression::parse("x3 * pi", 3, "integrand").unwrap();
        assert!((e.eval(&[0.0, 0.0, 2.0]) - 2.0 * std::f64::consts::PI).abs() < 1e-12);
    }

    #[test]
    fn rejects_unknown_variables_and_garbage() {
        let err = Expression::parse("x + z", 2, "integrand")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("unknown variable 'z'") && err.contains("x, y"),
            "{err}"
        );
        assert!(Expression::parse("x +* (", 1, "integrand").is_err());
        assert!(Expression::parse("  ", 1, "integrand").is_err());
        assert!(Expression::parse("x4", 3, "integrand").is_err());
    }

    #[test]
    fn rejects_ambiguous_powers() {
        for bad in [
            "-x^2",
            "exp(-x^2)",
            "2*-x^2",
            "x^-y^2",
            "-(x+1)^2",
            "-sin(x)^2",
            "2^3^2",
            "x^(2)^y",
        ] {
            let err = format!(
                "{:#}",
                Expression::parse(bad, 1, "f").map(|_| ()).unwrap_err()
            );
            assert!(err.contains("ambiguous"), "{bad}: {err}");
        }
        for ok in [
            "-(x^2)",
            "(-x)^2",
            "exp(-(x^2))",
            "x^-2",
            "1-x^2",
            "x^(2^x)",
            "2e-3*x^2",
            "(x)-x^2",
        ] {
            assert!(Expression::parse(ok, 1, "f").is_ok(), "{ok}");
        }
        let e = Expression::parse("1-x^2", 1, "f").unwrap();
        assert_eq!(e.eval(&[3.0]), -8.0);
        let e = Expression::parse("x^-2", 1, "f").unwrap();
        assert_eq!(e.eval(&[2.0]), 0.25);
    }

    #[test]
    fn constants() {
        assert_eq!(parse_constant("-2").unwrap(), -2.0);
        assert!((parse_constant("pi/2").unwrap() - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        assert!(parse_constant("two").is_err());
        assert_eq!(normalise("pi*x + spin + pi2"), "PI*x + spin + pi2");
        assert_eq!(normalise("2.5e-3*x + 1E2 + x2e1"), "0.0025*x + 100 + x2e1");
        let e = Expression::parse("2e-3*x^2", 1, "f").unwrap();
        assert!((e.eval(&[10.0]) - 0.2).abs() < 1e-12);
    }
}
