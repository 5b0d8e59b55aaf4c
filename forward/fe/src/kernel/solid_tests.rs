//! The solid kernel's tests: every cell in every kinematics, its tangent
//! against finite differences of its residual (distorted and curved cells),
//! and the combinations it refuses.

use super::*;
use crate::kernel::kernel_for;
use crate::material::{LawMaterial, NeoHookeanIso, PointMaterial};

fn quad4_x() -> Vec<[f64; 3]> {
    vec![
        [0.5, 0.0, 0.0],
        [1.6, 0.1, 0.0],
        [1.5, 1.2, 0.0],
        [0.4, 0.9, 0.0],
    ]
}

/// A distorted 9-node quadrilateral: the corners of `quad4_x`, edge
/// nodes moved off the midpoints, centre off the centroid.
fn quad9_x() -> Vec<[f64; 3]> {
    let c = quad4_x();
    let mid = |a: usize, b: usize, o: [f64; 2]| {
        [
            0.5 * (c[a][0] + c[b][0]) + o[0],
            0.5 * (c[a][1] + c[b][1]) + o[1],
            0.0,
        ]
    };
    let mut x = c.clone();
    x.push(mid(0, 1, [0.02, -0.03]));
    x.push(mid(1, 2, [0.04, 0.01]));
    x.push(mid(2, 3, [-0.01, 0.03]));
    x.push(mid(3, 0, [-0.02, 0.0]));
    x.push([1.02, 0.57, 0.0]);
    x
}

fn hex8_x() -> Vec<[f64; 3]> {
    let mut x: Vec<[f64; 3]> = crate::shape::HEX8_NODES
        .iter()
        .map(|p| [0.5 * (p[0] + 1.0), 0.6 * (p[1] + 1.0), 0.55 * (p[2] + 1.0)])
        .collect();
    x[6][0] += 0.1;
    x[1][1] -= 0.05;
    x[4][2] += 0.07;
    x
}

/// A distorted 27-node hexahedron: the corners of `hex8_x`, the other
/// nodes at the trilinear positions of their reference points, moved a
/// little (curved edges and faces).
fn hex27_x() -> Vec<[f64; 3]> {
    let c = hex8_x();
    crate::shape::HEX27_NODES
        .iter()
        .enumerate()
        .map(|(a, xi)| {
            let (n, _) = crate::shape::hex8(xi);
            let mut p = [0.0; 3];
            for (k, corner) in c.iter().enumerate() {
                for i in 0..3 {
                    p[i] += n[k] * corner[i];
                }
            }
            if a >= 8 {
                let s = a as f64;
                p[0] += 0.02 * (1.7 * s).sin();
                p[1] += 0.02 * (0.9 * s).cos();
                p[2] -= 0.015 * (1.3 * s).sin();
            }
            p
        })
        .collect()
}

fn displacements(x: &[[f64; 3]], dim: usize) -> Vec<[f64; 3]> {
    x.iter()
        .enumerate()
        .map(|(a, p)| {
            let s = a as f64;
            let mut u = [
                0.05 * (s * 1.3).sin() + 0.02 * p[1],
                -0.04 * (s * 0.7).cos() - 0.01 * p[0],
                0.03 * (s * 0.9).sin(),
            ];
            if dim == 2 {
                u[2] = 0.0;
            }
            u
        })
        .collect()
}

fn check_fd(
    cell: CellType,
    kin: Kinematics,
    pressure: PressureSpace,
    vol: Volumetric,
    mat: &dyn PointMaterial,
) {
    let k = kernel_for(cell, kin, pressure).unwrap();
    let x = match cell {
        CellType::Quad4 => quad4_x(),
        CellType::Quad9 => quad9_x(),
        CellType::Hex27 => hex27_x(),
        _ => hex8_x(),
    };
    let dim = kin.dim();
    let u = displacements(&x, dim);
    let np = k.element_unknowns(vol);
    let q: Vec<f64> = (0..np).map(|m| 0.3 - 0.2 * m as f64).collect();
    let input = |u: &[[f64; 3]], q: &[f64], out: &mut ElementOutput, t: bool| {
        let inp = ElementInput {
            element: 0,
            x: &x,
            u,
            q,
            material: mat,
            volumetric: vol,
            scale: 0.7,
            history: &[],
            dt: 0.0,
        };
        k.evaluate(&inp, t, out).unwrap();
    };
    let mut out = ElementOutput::default();
    input(&u, &q, &mut out, true);
    let n = out.residual.len();
    assert_eq!(n, x.len() * dim + np);
    let h = 1e-6;
    let (mut plus, mut minus) = (ElementOutput::default(), ElementOutput::default());
    let scale = out.tangent.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for c in 0..n {
        let (mut up, mut um, mut qp, mut qm) = (u.clone(), u.clone(), q.clone(), q.clone());
        if c < x.len() * dim {
            up[c / dim][c % dim] += h;
            um[c / dim][c % dim] -= h;
        } else {
            qp[c - x.len() * dim] += h;
            qm[c - x.len() * dim] -= h;
        }
        input(&up, &qp, &mut plus, false);
        input(&um, &qm, &mut minus, false);
        for r in 0..n {
            let fd = (plus.residual[r] - minus.residual[r]) / (2.0 * h);
            let kk = out.tangent[r * n + c];
            assert!(
                (fd - kk).abs() < 1e-6 * scale,
                "{cell:?} {kin:?} {pressure:?} {vol:?} K[{r}][{c}] = {kk}, fd {fd}"
            );
        }
    }
    for r in 0..n {
        for c in 0..n {
            let (a, b) = (out.tangent[r * n + c], out.tangent[c * n + r]);
            assert!(
                (a - b).abs() < 1e-10 * scale,
                "{cell:?} {kin:?} unsymmetric {r} {c}"
            );
        }
    }
}

/// Every kernel in every kinematics, exact and penalty: the tangent is
/// the derivative of the residual, and symmetric (energy-derived).
#[test]
fn tangents_match_finite_differences_in_every_kinematics() {
    let nh = NeoHookeanIso { c10: 0.5 };
    let yeoh = LawMaterial::new("reduced-polynomial:2".parse().unwrap(), vec![0.4, 0.2]).unwrap();
    let mats: [&dyn PointMaterial; 2] = [&nh, &yeoh];
    let two_d = [
        Kinematics::Axisymmetric,
        Kinematics::PlaneStrain { thickness: 2.0 },
    ];
    for mat in mats {
        for vol in [Volumetric::Incompressible, Volumetric::D1(0.05)] {
            for kin in two_d {
                check_fd(CellType::Quad4, kin, PressureSpace::P0, vol, mat);
                check_fd(CellType::Quad9, kin, PressureSpace::P1, vol, mat);
                check_fd(CellType::Quad9, kin, PressureSpace::P0, vol, mat);
            }
            check_fd(
                CellType::Hex8,
                Kinematics::ThreeD,
                PressureSpace::P0,
                vol,
                mat,
            );
            check_fd(
                CellType::Hex27,
                Kinematics::ThreeD,
                PressureSpace::P1,
                vol,
                mat,
            );
            let ps = Kinematics::PlaneStress { thickness: 0.5 };
            check_fd(CellType::Quad4, ps, PressureSpace::None, vol, mat);
            check_fd(CellType::Quad9, ps, PressureSpace::None, vol, mat);
        }
    }
}

#[test]
fn plane_stress_with_a_pressure_field_is_refused() {
    let ps = Kinematics::PlaneStress { thickness: 1.0 };
    assert!(kernel_for(CellType::Quad4, ps, PressureSpace::P0).is_err());
    assert!(kernel_for(
        CellType::Quad4,
        Kinematics::Axisymmetric,
        PressureSpace::None
    )
    .is_err());
    assert!(kernel_for(CellType::Hex8, Kinematics::Axisymmetric, PressureSpace::P0).is_err());
    assert!(kernel_for(
        CellType::Quad4,
        Kinematics::PlaneStrain { thickness: -1.0 },
        PressureSpace::P0
    )
    .is_err());
}
