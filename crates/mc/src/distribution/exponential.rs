//! The exponential distribution ([`Exponential`]), sampled by inversion:
//! x = -ln(1 - U) / λ.

use crate::error::{Error, Result};

/// The exponential distribution with rate λ: pdf λ e^(-λx) on x ≥ 0, CDF 1 - e^(-λx).
///
/// Sampled by inverting the CDF: U = 1 - e^(-λx) gives x = -ln(1 - U)/λ. With λ = 1 and
/// U = 0.75, x = ln 4.
///
/// ```
/// use pathlab_mc::distribution::Exponential;
/// let e = Exponential::new(1.0).unwrap();
/// assert!((e.sample(0.75) - 4f64.ln()).abs() < 1e-12);
/// assert!(Exponential::new(-1.0).is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Exponential {
    lambda: f64,
}

impl Exponential {
    /// The distribution with rate `lambda`, which must be finite and positive.
    pub fn new(lambda: f64) -> Result<Self> {
        if lambda.is_finite() && lambda > 0.0 {
            Ok(Exponential { lambda })
        } else {
            Err(Error::InvalidParameter {
                what: "exponential distribution",
                message: format!("rate lambda must be a finite number > 0, got {lambda}"),
            })
        }
    }

    /// The rate λ.
    pub fn lambda(&self) -> f64 {
        self.lambda
    }

    /// x = -ln(1 - u)/λ for u in [0, 1).
    #[inline]
    pub fn sample(&self, u: f64) -> f64 {
        -(-u).ln_1p() / self.lambda
    }

    /// The density λ e^(-λx) (0 for x < 0).
    #[inline]
    pub fn pdf(&self, x: f64) -> f64 {
        if x < 0.0 {
            0.0
        } else {
            self.lambda * (-self.lambda * x).exp()
        }
    }

    /// The CDF 1 - e^(-λx) (0 for x < 0).
    #[inline]
    pub fn cdf(&self, x: f64) -> f64 {
        if x < 0.0 {
            0.0
        } else {
            -(-self.lambda * x).exp_m1()
        }
    }

    /// The `u` that [`Exponential::sample`] maps to `x`: the CDF itself.
    #[inline]
    pub fn invert_sample(&self, x: f64) -> f64 {
        self.cdf(x)
    }

    /// E[X] = 1/λ.
    pub fn mean(&self) -> f64 {
        1.0 / self.lambda
    }

    /// Var[X] = 1/λ².
    pub fn variance(&self) -> f64 {
        1.0 / (self.lambda * self.lambda)
    }
}
