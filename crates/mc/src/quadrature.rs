//! Deterministic quadrature, for the integrals a renderer tabulates once (a rough interface's
//! albedo, say) where Monte Carlo noise would be baked into every image.

/// The nodes and weights of the `n`-point Gauss–Legendre rule on [-1, 1]: ∫ f ≈ Σ wᵢ f(xᵢ),
/// exact for polynomials of degree below 2n. Nodes in increasing order.
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        // Newton's method on P_n from the Chebyshev-like first guess.
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let pn = if n == 0 {
                1.0
            } else if n == 1 {
                x
            } else {
                p1
            };
            let pn1 = if n == 1 { 1.0 } else { p0 };
            dp = n as f64 * (x * pn - pn1) / (x * x - 1.0);
            let step = pn / dp;
            x -= step;
            if step.abs() < 1e-15 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        nodes[i] = -x;
        nodes[n - 1 - i] = x;
        weights[i] = w;
        weights[n - 1 - i] = w;
    }
    (nodes, weights)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrates_polynomials_exactly_and_smooth_functions_closely() {
        for n in [1, 2, 5, 16, 32] {
            let (x, w) = gauss_legendre(n);
            assert!((w.iter().sum::<f64>() - 2.0).abs() < 1e-12, "n = {n}");
            // ∫ x^k over [-1, 1] = 2/(k+1) for even k, exact up to degree 2n - 1.
            for k in (0..2 * n).step_by(2) {
                let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(k as i32)).sum();
                assert!(
                    (q - 2.0 / (k + 1) as f64).abs() < 1e-11,
                    "n = {n}, k = {k}: {q}"
                );
            }
            assert!(x.windows(2).all(|p| p[0] < p[1]));
        }
        let (x, w) = gauss_legendre(20);
        let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.exp()).sum();
        assert!((q - (1f64.exp() - (-1f64).exp())).abs() < 1e-13);
    }
}
