//! Gauss-Legendre quadrature on the reference square `[-1, 1]^2`.

/// Points and weights of the 2 x 2 Gauss rule (exact for polynomials of
/// degree 3 in each variable; Hughes, *The Finite Element Method*, table 3.8.1).
pub fn gauss_2x2() -> [([f64; 2], f64); 4] {
    let g = 1.0 / 3f64.sqrt();
    [
        ([-g, -g], 1.0),
        ([g, -g], 1.0),
        ([g, g], 1.0),
        ([-g, g], 1.0),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn integrates_cubic_exactly() {
        // integral of x^3 y^2 + x^2 y^2 + 1 over [-1,1]^2 = 0 + 4/9 + 4
        let s: f64 = gauss_2x2()
            .iter()
            .map(|([x, y], w)| w * (x.powi(3) * y * y + x * x * y * y + 1.0))
            .sum();
        assert!((s - (4.0 / 9.0 + 4.0)).abs() < 1e-14);
    }
}
