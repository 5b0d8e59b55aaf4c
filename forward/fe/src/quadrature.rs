//! Gauss-Legendre quadrature on the reference cells `[-1, 1]^d`: tensor
//! products of the one-dimensional rules (Hughes, *The Finite Element
//! Method*, 2000, table 3.8.1; Abramowitz & Stegun 25.4.30).

use crate::mesh::CellType;

/// Points and weights of the `n`-point Gauss-Legendre rule on `[-1, 1]`
/// (`n` in 1..=3; exact for polynomials of degree `2 n - 1`).
pub fn gauss_1d(n: usize) -> Vec<(f64, f64)> {
    match n {
        1 => vec![(0.0, 2.0)],
        2 => {
            let g = 1.0 / 3f64.sqrt();
            vec![(-g, 1.0), (g, 1.0)]
        }
        _ => {
            let g = (0.6f64).sqrt();
            vec![(-g, 5.0 / 9.0), (0.0, 8.0 / 9.0), (g, 5.0 / 9.0)]
        }
    }
}

/// A quadrature rule on a reference cell: points (unused coordinates zero)
/// and weights.
#[derive(Debug, Clone, PartialEq)]
pub struct QuadratureRule {
    pub points: Vec<[f64; 3]>,
    pub weights: Vec<f64>,
}

impl QuadratureRule {
    /// The tensor-product Gauss rule with `n` points per direction on the
    /// reference cell of `cell`.
    pub fn gauss(cell: CellType, n: usize) -> QuadratureRule {
        let g = gauss_1d(n);
        let mut points = Vec::new();
        let mut weights = Vec::new();
        match cell.dim() {
            1 => {
                for &(x, w) in &g {
                    points.push([x, 0.0, 0.0]);
                    weights.push(w);
                }
            }
            2 => {
                // counter-clockwise order for 2 x 2 (the order of the
                // original Q1/P0 element, kept so that its sums are unchanged)
                if n == 2 {
                    let s = g[1].0;
                    for p in [[-s, -s], [s, -s], [s, s], [-s, s]] {
                        points.push([p[0], p[1], 0.0]);
                        weights.push(1.0);
                    }
                } else {
                    for &(y, wy) in &g {
                        for &(x, wx) in &g {
                            points.push([x, y, 0.0]);
                            weights.push(wx * wy);
                        }
                    }
                }
            }
            _ => {
                for &(z, wz) in &g {
                    for &(y, wy) in &g {
                        for &(x, wx) in &g {
                            points.push([x, y, z]);
                            weights.push(wx * wy * wz);
                        }
                    }
                }
            }
        }
        QuadratureRule { points, weights }
    }

    /// The rule a solid cell of this type is integrated with: full
    /// integration (2 points per direction for linear cells, 3 for quadratic).
    pub fn for_cell(cell: CellType) -> QuadratureRule {
        match cell {
            CellType::Line3 | CellType::Quad9 | CellType::Hex27 => Self::gauss(cell, 3),
            _ => Self::gauss(cell, 2),
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.weights.len()
    }

    /// True for an empty rule.
    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn integrate(rule: &QuadratureRule, f: impl Fn([f64; 3]) -> f64) -> f64 {
        rule.points
            .iter()
            .zip(&rule.weights)
            .map(|(p, w)| w * f(*p))
            .sum()
    }

    #[test]
    fn rules_integrate_their_polynomial_degree_exactly() {
        // integral over [-1,1]^2 of x^3 y^2 + x^2 y^2 + 1 = 4/9 + 4 (2 x 2 rule)
        let q4 = QuadratureRule::gauss(CellType::Quad4, 2);
        let s = integrate(&q4, |[x, y, _]| x.powi(3) * y * y + x * x * y * y + 1.0);
        assert!((s - (4.0 / 9.0 + 4.0)).abs() < 1e-14);
        // 3 x 3: x^4 y^4 -> (2/5)^2; 2 x 2 would give (2/9)^2
        let q9 = QuadratureRule::for_cell(CellType::Quad9);
        assert_eq!(q9.len(), 9);
        let s = integrate(&q9, |[x, y, _]| x.powi(4) * y.powi(4) + x.powi(5));
        assert!((s - 0.16).abs() < 1e-14, "{s}");
        let h = QuadratureRule::for_cell(CellType::Hex8);
        assert_eq!(h.len(), 8);
        let s = integrate(&h, |[x, y, z]| x * x * y * y * z * z + 1.0);
        assert!((s - (8.0 / 27.0 + 8.0)).abs() < 1e-14);
        let l = QuadratureRule::for_cell(CellType::Line3);
        let s = integrate(&l, |[x, _, _]| x.powi(4));
        assert!((s - 0.4).abs() < 1e-15);
    }
}
