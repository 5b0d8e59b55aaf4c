//! Patch tests and homogeneous-state checks of every element kernel in every
//! kinematics.
//!
//! * Patch tests: on a distorted patch of cells, the boundary nodes are
//!   given the displacement of a homogeneous deformation `u = (F - I) X`;
//!   the other nodes must reproduce it to round-off (an isoparametric
//!   element reproduces affine fields, and a uniform stress is in
//!   equilibrium with itself). With exact incompressibility a fully
//!   prescribed boundary leaves the constant pressure undetermined, so some
//!   boundary components are left free where the homogeneous state (with
//!   its own pressure) is traction free ([`Free`]), and the free nodes are
//!   checked too. In 3D the top normal alone is not enough: a 3 x 3 x 3
//!   Q1/P0 patch then has 28 free displacements against 27 pressure
//!   constraints, and the linear path through non-isochoric states ends on
//!   another (checkerboard-pressure) solution of the discrete equations, so
//!   the 3D patch is a column whose path stays homogeneous.
//! * The cube in uniaxial and equibiaxial loading and the plane-stress strip
//!   in uniaxial tension against the analytic homogeneous answers of the
//!   incompressible laws (`palpate_material::homogeneous`).

use std::sync::Arc;

use palpate_fe::body::{RegionMaterial, SolidBody};
use palpate_fe::dofs::Dirichlet;
use palpate_fe::kernel::{kernel_for, PressureSpace};
use palpate_fe::kinematics::Kinematics;
use palpate_fe::material::{NeoHookeanIso, PointMaterial};
use palpate_fe::mesh::{CellType, Mesh};
use palpate_fe::{stepper, LawMaterial, LoadPath, SolverOptions, System};
use palpate_material::{arruda_boyce, homogeneous, Law, Volumetric};

const C10: f64 = 0.01;
const MU: f64 = 2.0 * C10;

fn options() -> SolverOptions {
    SolverOptions {
        max_step: 0.5,
        first_step: 0.5,
        tolerance: 1e-12,
        // never accept a stagnated Newton iteration
        stagnation_tolerance: 1e-12,
        ..SolverOptions::default()
    }
}

fn mooney_rivlin() -> Arc<dyn PointMaterial> {
    Arc::new(LawMaterial::new(Law::MooneyRivlin, vec![0.8 * C10, 0.2 * C10]).unwrap())
}

/// A penalty with bulk modulus `20 mu` (`K = 2 / D1`).
fn d1() -> Volumetric {
    Volumetric::D1(2.0 / (20.0 * MU))
}

/// Deterministic offsets in `[-1, 1]` (a small linear congruential sequence).
fn jitter(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// A 3 x 3 patch of unit quadrilaterals on `[x0, x0 + 3] x [0, 3]` with its
/// interior nodes moved; for `Quad9`, the order-elevated patch with its
/// mid-edge and centre nodes moved too (boundary mid-nodes along their edge,
/// so the sides stay straight).
fn patch_2d(cell: CellType, x0: f64) -> Mesh {
    let xs: Vec<f64> = (0..4).map(|i| x0 + i as f64).collect();
    let ys: Vec<f64> = (0..4).map(|i| i as f64).collect();
    let mut m = Mesh::tensor(&xs, &ys);
    let moves = [(0.2, -0.15), (-0.1, 0.25), (0.15, 0.1), (-0.25, -0.2)];
    for (k, (i, j)) in [(1, 1), (2, 1), (1, 2), (2, 2)].into_iter().enumerate() {
        let n = j * 4 + i;
        m.nodes[n][0] += moves[k].0;
        m.nodes[n][1] += moves[k].1;
    }
    if cell == CellType::Quad9 {
        let corners = m.nodes.len();
        m = m.to_quadratic().unwrap();
        let mut seed = 7;
        for n in corners..m.nodes.len() {
            let p = m.nodes[n];
            let (dx, dy) = (0.08 * jitter(&mut seed), 0.08 * jitter(&mut seed));
            let on_x = p[0] == xs[0] || p[0] == xs[3];
            let on_y = p[1] == ys[0] || p[1] == ys[3];
            if !on_x {
                m.nodes[n][0] += dx;
            }
            if !on_y {
                m.nodes[n][1] += dy;
            }
        }
    }
    assert_eq!(m.cell_type, cell);
    m
}

/// A 3 x 3 x 3 patch of unit hexahedra with its eight interior nodes moved.
fn patch_3d() -> Mesh {
    let xs = [0.0, 1.0, 2.0, 3.0];
    let mut m = Mesh::tensor3(&xs, &xs, &xs);
    let mut seed = 11;
    for k in 1..3 {
        for j in 1..3 {
            for i in 1..3 {
                let n = (k * 4 + j) * 4 + i;
                for c in 0..3 {
                    m.nodes[n][c] += 0.25 * jitter(&mut seed);
                }
            }
        }
    }
    m
}

/// [`patch_3d`] with 27-node cells whose new interior nodes are moved off
/// their midpoints too (curved edges and faces inside the patch).
fn patch_3d_quadratic() -> Mesh {
    let mut m = patch_3d().to_quadratic().unwrap();
    let mut seed = 5;
    for n in 64..m.nodes.len() {
        let p = m.nodes[n];
        let inside = p.iter().all(|&v| v != 0.0 && v != 3.0);
        for c in 0..3 {
            let d = 0.06 * jitter(&mut seed);
            if inside {
                m.nodes[n][c] += d;
            }
        }
    }
    m
}

/// `F` scaled to `det F = 1`.
fn isochoric<const D: usize>(f: [[f64; D]; D]) -> [[f64; D]; D] {
    let det = if D == 2 {
        f[0][0] * f[1][1] - f[0][1] * f[1][0]
    } else {
        let g = |i: usize, j: usize| f[i][j];
        g(0, 0) * (g(1, 1) * g(2, 2) - g(1, 2) * g(2, 1))
            - g(0, 1) * (g(1, 0) * g(2, 2) - g(1, 2) * g(2, 0))
            + g(0, 2) * (g(1, 0) * g(2, 1) - g(1, 1) * g(2, 0))
    };
    let s = det.powf(-1.0 / D as f64);
    f.map(|row| row.map(|v| v * s))
}

/// Which boundary displacement components are left free (see the module
/// docs); the last coordinate is "up".
#[derive(Debug, Clone, Copy, PartialEq)]
enum Free {
    /// Every boundary node fully prescribed (penalty and plane stress).
    Nothing,
    /// The normal component of the top side's inner nodes free: the
    /// homogeneous pressure makes `P_yY` vanish.
    TopNormal,
    /// Only the bottom and the in-plane components of the lateral sides
    /// prescribed: for `F = [[A, 0], [0, lambda]]` the homogeneous state has
    /// `P_zX = P_zY = P_xZ = P_yZ = 0`, and its pressure makes `P_zZ`
    /// vanish; every intermediate state of the path is homogeneous too
    /// (`F_zz` follows from `det F = 1`).
    Column,
}

/// Patch test of `kernel` (cell, kinematics, pressure space) with the
/// homogeneous deformation gradient `f` (in-plane `D x D`, the out-of-plane
/// stretch following from the kinematics). Returns the largest nodal error
/// relative to the largest displacement.
fn patch<const D: usize>(
    mesh: Mesh,
    kinematics: Kinematics,
    pressure: PressureSpace,
    volumetric: Volumetric,
    free: Free,
    f: [[f64; D]; D],
) -> f64 {
    patch_with(
        mooney_rivlin(),
        mesh,
        kinematics,
        pressure,
        volumetric,
        free,
        f,
    )
}

/// [`patch`] with a given material (its shear modulus near [`MU`]).
fn patch_with<const D: usize>(
    material: Arc<dyn PointMaterial>,
    mesh: Mesh,
    kinematics: Kinematics,
    pressure: PressureSpace,
    volumetric: Volumetric,
    free: Free,
    f: [[f64; D]; D],
) -> f64 {
    let exact = matches!(volumetric, Volumetric::Incompressible);
    let mut mesh = mesh;
    let lo: [f64; 3] = std::array::from_fn(|c| {
        mesh.nodes
            .iter()
            .map(|p| p[c])
            .fold(f64::INFINITY, f64::min)
    });
    let hi: [f64; 3] = std::array::from_fn(|c| {
        mesh.nodes
            .iter()
            .map(|p| p[c])
            .fold(f64::NEG_INFINITY, f64::max)
    });
    let on = |p: &[f64; 3], c: usize| p[c] == lo[c] || p[c] == hi[c];
    let exact_u = |p: &[f64; 3]| -> [f64; 3] {
        std::array::from_fn(|i| {
            if i < D {
                (0..D).map(|j| f[i][j] * p[j]).sum::<f64>() - p[i]
            } else {
                0.0
            }
        })
    };
    let top = D - 1;
    let mut bcs = Vec::new();
    for n in 0..mesh.nodes.len() {
        let p = mesh.nodes[n];
        let lateral = (0..top).any(|c| on(&p, c));
        let bottom = p[top] == lo[top];
        let prescribed = |c: usize| match free {
            Free::Nothing => lateral || on(&p, top),
            Free::TopNormal => lateral || bottom || (on(&p, top) && c != top),
            Free::Column => bottom || (lateral && c != top),
        };
        let name = format!("n{n}");
        let u = exact_u(&p);
        for c in (0..D).filter(|&c| prescribed(c)) {
            bcs.push(Dirichlet::driven(&name, c, 0, u[c]));
        }
        mesh.node_sets.insert(name, vec![n]);
    }
    let expected: Vec<[f64; 3]> = mesh.nodes.iter().map(exact_u).collect();
    let scale = expected
        .iter()
        .flat_map(|u| u.iter())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let kernel = kernel_for(mesh.cell_type, kinematics, pressure).unwrap();
    let mut body = SolidBody::new("body", &mesh, &["body"], kernel, exact).unwrap();
    body.set_material(
        "body",
        RegionMaterial {
            material,
            volumetric,
        },
    )
    .unwrap();
    let h = mesh.min_edge();
    let mut sys = System::new(mesh, D, vec![Box::new(body)], &bcs, 1).unwrap();
    sys.force_floor = 1e-6 * MU * h * h;
    let path = LoadPath::from_drive(&[1.0]);
    if let Err(e) = stepper::run(&mut sys, &path, &options(), &mut |_| vec![], None) {
        panic!("{kinematics:?} {pressure:?} {volumetric:?}: {:?}", e.error);
    }
    let u = sys.displacements();
    let err = (0..u.len())
        .flat_map(|n| (0..D).map(move |c| (n, c)))
        .map(|(n, c)| (u[n][c] - expected[n][c]).abs())
        .fold(0.0f64, f64::max)
        / scale;
    // A homogeneous state has the same mean stress in every cell.
    let body = sys.part::<SolidBody>(0).unwrap();
    let s = body.mean_cauchy_stresses(&sys.u, D);
    let spread = s
        .iter()
        .flat_map(|a| a.iter().zip(&s[0]).map(|(x, y)| (x - y).abs()))
        .fold(0.0f64, f64::max)
        / MU;
    assert!(
        spread < 1e-8,
        "{kinematics:?} {pressure:?} {volumetric:?}: cell stresses differ by {spread:.2e} mu"
    );
    err
}

fn assert_patch(err: f64, what: &str) {
    assert!(
        err < 1e-10,
        "{what}: interior nodes off the homogeneous field by {err:.2e} (relative)"
    );
}

/// `u_r = a r`, `u_z = b z`: the homogeneous states of a body of revolution
/// (equal radial and hoop stretches); `b` from `det F = (1 + a)^2 (1 + b) = 1`
/// when `isochoric`.
fn axisymmetric_f(isochoric: bool) -> [[f64; 2]; 2] {
    let a = 0.15;
    let b = if isochoric {
        1.0 / ((1.0 + a) * (1.0 + a)) - 1.0
    } else {
        -0.1
    };
    [[1.0 + a, 0.0], [0.0, 1.0 + b]]
}

const F2: [[f64; 2]; 2] = [[1.2, 0.25], [-0.1, 0.9]];
const F3: [[f64; 3]; 3] = [[1.15, 0.2, -0.05], [0.1, 0.9, 0.15], [-0.1, 0.05, 1.1]];
const F3_COLUMN: [[f64; 3]; 3] = [[1.15, 0.2, 0.0], [-0.1, 0.95, 0.0], [0.0, 0.0, 1.1]];

#[test]
fn patch_axisymmetric() {
    for (cell, pressure) in [
        (CellType::Quad4, PressureSpace::P0),
        (CellType::Quad9, PressureSpace::P1),
    ] {
        for vol in [Volumetric::Incompressible, d1()] {
            let exact = matches!(vol, Volumetric::Incompressible);
            let err = patch(
                patch_2d(cell, 0.5),
                Kinematics::Axisymmetric,
                pressure,
                vol,
                if exact {
                    Free::TopNormal
                } else {
                    Free::Nothing
                },
                axisymmetric_f(exact),
            );
            assert_patch(err, &format!("axisymmetric {cell:?} {vol:?}"));
        }
    }
}

#[test]
fn patch_plane_strain() {
    let k = Kinematics::PlaneStrain { thickness: 2.0 };
    for (cell, pressure) in [
        (CellType::Quad4, PressureSpace::P0),
        (CellType::Quad9, PressureSpace::P1),
    ] {
        for vol in [Volumetric::Incompressible, d1()] {
            let (f, free) = if matches!(vol, Volumetric::Incompressible) {
                (isochoric(F2), Free::TopNormal)
            } else {
                (F2, Free::Nothing)
            };
            let err = patch(patch_2d(cell, 0.0), k, pressure, vol, free, f);
            assert_patch(err, &format!("plane strain {cell:?} {vol:?}"));
        }
    }
}

#[test]
fn patch_plane_stress() {
    let k = Kinematics::PlaneStress { thickness: 0.5 };
    for cell in [CellType::Quad4, CellType::Quad9] {
        for vol in [Volumetric::Incompressible, d1()] {
            let err = patch(
                patch_2d(cell, 0.0),
                k,
                PressureSpace::None,
                vol,
                Free::Nothing,
                F2,
            );
            assert_patch(err, &format!("plane stress {cell:?} {vol:?}"));
        }
    }
}

#[test]
fn patch_three_d() {
    for vol in [Volumetric::Incompressible, d1()] {
        // exact: a column with in-plane shear (see `Free::Column`)
        let (f, free) = if matches!(vol, Volumetric::Incompressible) {
            (isochoric(F3_COLUMN), Free::Column)
        } else {
            (F3, Free::Nothing)
        };
        // Hex8 with a constant pressure, Hex27 (the same cells made
        // triquadratic, interior mid-nodes moved) with a linear one
        for (mesh, pressure) in [
            (patch_3d(), PressureSpace::P0),
            (patch_3d_quadratic(), PressureSpace::P1),
        ] {
            let cell = mesh.cell_type;
            let err = patch(mesh, Kinematics::ThreeD, pressure, vol, free, f);
            assert_patch(err, &format!("3D {cell:?} {vol:?}"));
        }
    }
}

/// The patch tests of every law with a shear modulus of [`MU`]: plane strain
/// (Q1/P0 and Q2/P1, exact and penalty incompressibility) and the exact 3D
/// column (Hex8/P0), with parameters that make each law's nonlinear terms
/// matter at the patch's stretches (Gent's `Jm` of 1.5 is reached at
/// `I1 - 3 = 1.5`; the patch's `I1 - 3` is about 0.2).
#[test]
fn patch_with_every_law() {
    let laws: [(Law, Vec<f64>); 9] = [
        (Law::NeoHookean, vec![C10]),
        (Law::MooneyRivlin, vec![0.8 * C10, 0.2 * C10]),
        (Law::ReducedPolynomial(3), vec![C10, -0.1 * C10, 0.05 * C10]),
        (
            Law::ArrudaBoyce,
            vec![MU / arruda_boyce::initial_shear_modulus(1.0, 1.5), 1.5],
        ),
        (Law::Ogden(2), vec![0.7 * MU, 3.0, 0.3 * MU, -2.0]),
        (Law::Gent, vec![MU, 1.5]),
        (Law::VerondaWestmann, vec![MU / 2.0, 2.0]),
        (Law::Humphrey, vec![MU / 4.0, 2.0]),
        (Law::Humphrey, vec![MU / 40.0, 20.0]),
    ];
    let k = Kinematics::PlaneStrain { thickness: 2.0 };
    for (law, params) in laws {
        let material: Arc<dyn PointMaterial> =
            Arc::new(LawMaterial::new(law, params.clone()).unwrap());
        assert!((material.shear_modulus() - MU).abs() < 1e-12 * MU, "{law}");
        for (cell, pressure) in [
            (CellType::Quad4, PressureSpace::P0),
            (CellType::Quad9, PressureSpace::P1),
        ] {
            for vol in [Volumetric::Incompressible, d1()] {
                let (f, free) = if matches!(vol, Volumetric::Incompressible) {
                    (isochoric(F2), Free::TopNormal)
                } else {
                    (F2, Free::Nothing)
                };
                let err = patch_with(
                    material.clone(),
                    patch_2d(cell, 0.0),
                    k,
                    pressure,
                    vol,
                    free,
                    f,
                );
                assert_patch(
                    err,
                    &format!("{law} {params:?} plane strain {cell:?} {vol:?}"),
                );
            }
        }
        let err = patch_with(
            material,
            patch_3d(),
            Kinematics::ThreeD,
            PressureSpace::P0,
            Volumetric::Incompressible,
            Free::Column,
            isochoric(F3_COLUMN),
        );
        assert_patch(err, &format!("{law} {params:?} 3D Hex8"));
    }
}

/// The unit cube of 2 x 2 x 2 hexahedra (centre node moved) with the
/// symmetry planes x = 0, y = 0, z = 0 held in their normal component, of
/// incompressible neo-Hookean `C10`, and exact incompressibility.
fn cube(bcs: &[Dirichlet]) -> System {
    let xs = [0.0, 0.5, 1.0];
    let mut mesh = Mesh::tensor3(&xs, &xs, &xs);
    mesh.nodes[13] = [0.55, 0.42, 0.58];
    let kernel = kernel_for(CellType::Hex8, Kinematics::ThreeD, PressureSpace::P0).unwrap();
    let mut body = SolidBody::new("body", &mesh, &["body"], kernel, true).unwrap();
    body.set_material(
        "body",
        RegionMaterial {
            material: Arc::new(NeoHookeanIso { c10: C10 }),
            volumetric: Volumetric::Incompressible,
        },
    )
    .unwrap();
    let mut all = vec![
        Dirichlet::fixed("x0", 0),
        Dirichlet::fixed("y0", 1),
        Dirichlet::fixed("bottom", 2),
    ];
    all.extend_from_slice(bcs);
    let mut sys = System::new(mesh, 3, vec![Box::new(body)], &all, 1).unwrap();
    sys.force_floor = 1e-6 * MU * 0.25;
    sys
}

/// Sum of the internal forces of component `c` over node set `set`.
fn face_force(sys: &System, set: &str, c: usize) -> f64 {
    let f = sys.internal_forces();
    sys.mesh
        .node_set(set)
        .unwrap()
        .iter()
        .map(|&n| f[n * 3 + c])
        .sum()
}

fn close(fe: f64, exact: f64, tol: f64, what: &str) {
    assert!(
        (fe - exact).abs() <= tol * exact.abs(),
        "{what}: FE {fe:.10e} against {exact:.10e} (relative error {:.2e})",
        (fe - exact) / exact
    );
}

#[test]
fn cube_uniaxial_and_equibiaxial() {
    let nh = Law::NeoHookean;
    for lambda in [1.3f64, 0.8] {
        let analytic = 2.0 * C10 * (lambda - lambda.powi(-2));
        close(
            homogeneous::uniaxial(&nh, &[C10], lambda),
            analytic,
            1e-12,
            "homogeneous::uniaxial",
        );
        let mut sys = cube(&[Dirichlet::driven("top", 2, 0, 1.0)]);
        let path = LoadPath::from_drive(&[lambda - 1.0]);
        let out = stepper::run(
            &mut sys,
            &path,
            &options(),
            &mut |s| vec![s.channel_reaction(0)],
            None,
        )
        .unwrap_or_else(|e| panic!("uniaxial {lambda}: {:?}", e.error));
        // unit area: the reaction is the nominal stress
        close(out[0][0], analytic, 1e-6, &format!("uniaxial {lambda}"));
        // lateral faces free: they move to lambda^-1/2
        let u = sys.displacements();
        let t = lambda.powf(-0.5) - 1.0;
        for n in sys.mesh.node_set("x1").unwrap() {
            assert!(
                (u[*n][0] - t).abs() < 1e-9,
                "uniaxial {lambda}: x1 at {}",
                u[*n][0]
            );
        }

        let analytic = 2.0 * C10 * (lambda - lambda.powi(-5));
        close(
            homogeneous::equibiaxial(&nh, &[C10], lambda),
            analytic,
            1e-12,
            "homogeneous::equibiaxial",
        );
        let mut sys = cube(&[
            Dirichlet::driven("x1", 0, 0, 1.0),
            Dirichlet::driven("y1", 1, 0, 1.0),
        ]);
        let out = stepper::run(
            &mut sys,
            &path,
            &options(),
            &mut |s| vec![s.channel_reaction(0)],
            None,
        )
        .unwrap_or_else(|e| panic!("equibiaxial {lambda}: {:?}", e.error));
        close(
            out[0][0] / 2.0,
            analytic,
            1e-6,
            &format!("equibiaxial {lambda}"),
        );
        close(face_force(&sys, "x1", 0), analytic, 1e-6, "equibiaxial x1");
        close(face_force(&sys, "y1", 1), analytic, 1e-6, "equibiaxial y1");
        let u = sys.displacements();
        let t = lambda.powi(-2) - 1.0;
        for n in sys.mesh.node_set("top").unwrap() {
            assert!(
                (u[*n][2] - t).abs() < 1e-9,
                "equibiaxial {lambda}: top at {}",
                u[*n][2]
            );
        }
    }
}

/// The plane-stress strip `[0, L] x [0, H]` of thickness `t`, held at
/// x = 0 in x and at the corner (0, 0) in y, pulled at x = L: the nominal
/// force is the incompressible uniaxial stress times `H t`.
#[test]
fn plane_stress_strip_uniaxial() {
    let (l, h, t) = (3.0, 1.0, 0.4);
    let laws: [(Law, Vec<f64>); 5] = [
        (Law::NeoHookean, vec![C10]),
        (Law::ReducedPolynomial(3), vec![C10, -0.1 * C10, 0.05 * C10]),
        (Law::Gent, vec![MU, 1.5]),
        (Law::VerondaWestmann, vec![MU / 2.0, 2.0]),
        (Law::Humphrey, vec![MU / 4.0, 2.0]),
    ];
    for cell in [CellType::Quad4, CellType::Quad9] {
        for (law, params) in &laws {
            for lambda in [1.3f64, 0.8] {
                let mut mesh = Mesh::tensor(&[0.0, 1.0, 2.0, l], &[0.0, 0.5, h]);
                if cell == CellType::Quad9 {
                    mesh = mesh.to_quadratic().unwrap();
                }
                mesh.node_sets.insert("corner".into(), vec![0]);
                let kernel = kernel_for(
                    cell,
                    Kinematics::PlaneStress { thickness: t },
                    PressureSpace::None,
                )
                .unwrap();
                let mut body = SolidBody::new("body", &mesh, &["body"], kernel, true).unwrap();
                let material: Arc<dyn PointMaterial> = if *law == Law::NeoHookean {
                    Arc::new(NeoHookeanIso { c10: params[0] })
                } else {
                    Arc::new(LawMaterial::new(*law, params.clone()).unwrap())
                };
                body.set_material(
                    "body",
                    RegionMaterial {
                        material,
                        volumetric: Volumetric::Incompressible,
                    },
                )
                .unwrap();
                let bcs = [
                    Dirichlet::fixed("axis", 0),
                    Dirichlet::fixed("corner", 1),
                    Dirichlet::driven("side", 0, 0, l),
                ];
                let mut sys = System::new(mesh, 2, vec![Box::new(body)], &bcs, 1).unwrap();
                sys.force_floor = 1e-6 * MU * 0.25;
                let path = LoadPath::from_drive(&[lambda - 1.0]);
                let out = stepper::run(
                    &mut sys,
                    &path,
                    &options(),
                    &mut |s| vec![s.channel_reaction(0)],
                    None,
                )
                .unwrap_or_else(|e| panic!("{cell:?} {law:?} {lambda}: {:?}", e.error));
                let stress = homogeneous::uniaxial(law, params, lambda);
                if *law == Law::NeoHookean {
                    close(
                        stress,
                        2.0 * C10 * (lambda - lambda.powi(-2)),
                        1e-12,
                        "neo-Hookean",
                    );
                }
                // reaction = sum scale * f_int with scale L: L x the force
                close(
                    out[0][0] / l,
                    stress * h * t,
                    1e-6,
                    &format!("{cell:?} {law:?} {lambda}"),
                );
                let u = sys.displacements();
                let lateral = lambda.powf(-0.5) - 1.0;
                for n in sys.mesh.node_set("top").unwrap() {
                    assert!(
                        (u[*n][1] - h * lateral).abs() < 1e-9,
                        "{cell:?} {law:?} {lambda}: top at {}",
                        u[*n][1]
                    );
                }
            }
        }
    }
}
