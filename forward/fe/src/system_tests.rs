//! The assembled global tangent (bodies and contact, stick and slip, every
//! kinematics) against finite differences of the global residual, and the
//! exactness of a rollback.

use std::sync::Arc;

use palpate_material::Volumetric;

use super::*;
use crate::body::{RegionMaterial, SolidBody};
use crate::contact::{ContactOptions, ContactPoints, RigidContact};
use crate::dofs::Dirichlet;
use crate::kernel::{kernel_for, PressureSpace};
use crate::kinematics::Kinematics;
use crate::material::NeoHookeanIso;
use crate::mesh::{CellType, Grading};
use crate::motion::ToolMotion;
use crate::stepper::{self, LoadPath};
use crate::surface::{Profile2d, Revolution3d, RigidSurface, Wheel2d};
use crate::tool::ToolShape;

struct Case {
    kin: Kinematics,
    cell: CellType,
    exact: bool,
    friction: f64,
}

/// A 4 x 2 block (2D) or 2 x 2 x 2 box (3D), bottom fixed, a rigid tool
/// pressed into the top by channel 0 and moved sideways by channel 1.
fn system(c: &Case) -> System {
    let dim = c.kin.dim();
    let mut mesh = if dim == 2 {
        Mesh::graded_rectangle(4.0, 2.0, Grading::uniform(4.0, 4), Grading::uniform(2.0, 2))
            .unwrap()
    } else {
        Mesh::graded_box(
            2.0,
            2.0,
            2.0,
            Grading::uniform(2.0, 2),
            Grading::uniform(2.0, 2),
            Grading::uniform(2.0, 2),
        )
        .unwrap()
    };
    if c.cell == CellType::Quad9 {
        mesh = mesh.to_quadratic().unwrap();
    }
    let pressure = if !c.kin.needs_pressure() {
        PressureSpace::None
    } else if c.cell == CellType::Quad9 {
        PressureSpace::P1
    } else {
        PressureSpace::P0
    };
    let mut body = SolidBody::new(
        "body",
        &mesh,
        &["body"],
        kernel_for(c.cell, c.kin, pressure).unwrap(),
        c.exact,
    )
    .unwrap();
    let mu = 1.0;
    body.set_material(
        "body",
        RegionMaterial {
            material: Arc::new(NeoHookeanIso { c10: 0.5 * mu }),
            volumetric: if c.exact {
                Volumetric::Incompressible
            } else {
                Volumetric::D1(0.1)
            },
        },
    )
    .unwrap();
    let (surface, origin, bcs): (Box<dyn RigidSurface>, [f64; 3], Vec<Dirichlet>) = match c.kin {
        Kinematics::ThreeD => (
            Box::new(Revolution3d(ToolShape::Sphere { radius: 1.5 })),
            [0.3, 0.4, 2.0],
            (0..3).map(|k| Dirichlet::fixed("bottom", k)).collect(),
        ),
        Kinematics::Axisymmetric => (
            Box::new(Profile2d(ToolShape::n1_needle())),
            [0.0, 2.0, 0.0],
            vec![
                Dirichlet::fixed("axis", 0),
                Dirichlet::fixed("bottom", 0),
                Dirichlet::fixed("bottom", 1),
            ],
        ),
        _ => (
            Box::new(Wheel2d { radius: 1.5 }),
            [1.7, 2.0, 0.0],
            vec![Dirichlet::fixed("bottom", 0), Dirichlet::fixed("bottom", 1)],
        ),
    };
    let sideways = if c.kin == Kinematics::Axisymmetric {
        // an axisymmetric tool can only move along the axis: rotate it instead
        [0.0, 0.0, 0.0]
    } else {
        [1.0, 0.0, 0.0]
    };
    let mut translation = vec![(0, [0.0, 0.0, -1.0])];
    if dim == 2 {
        translation[0].1 = [0.0, -1.0, 0.0];
    }
    if sideways != [0.0; 3] {
        translation.push((1, sideways));
    }
    // an unused channel is refused: the axisymmetric case has only channel 0
    let channels = translation.len();
    let motion = ToolMotion::translating(origin, translation);
    let contact = RigidContact::new(
        "tool",
        surface,
        motion,
        &mesh,
        "top",
        c.kin,
        ContactOptions {
            friction: c.friction,
            penalty_normal: 20.0,
            penalty_tangent: 20.0,
            penetration_tol: 1e-6,
            points: ContactPoints::EdgeGauss,
        },
        channels,
    )
    .unwrap();
    let mut sys = System::new(
        mesh,
        dim,
        vec![Box::new(body), Box::new(contact)],
        &bcs,
        channels,
    )
    .unwrap();
    sys.force_floor = 1e-6;
    sys
}

/// The loading state with channel values `values`, cut to the channels `sys` has.
fn target(sys: &System, values: &[f64]) -> Target {
    Target {
        channels: values[..sys.committed.channels.len()].to_vec(),
        time: 0.0,
        dt: 0.0,
    }
}

fn pressed(sys: &mut System, sideways: f64) {
    let n = sys.committed.channels.len();
    let path = LoadPath {
        tau: vec![0.1, 0.2, 0.2 + sideways],
        values: [[0.1, 0.0], [0.2, 0.0], [0.2, sideways]]
            .iter()
            .map(|v| v[..n].to_vec())
            .collect(),
        time: vec![0.0; 3],
    };
    let opts = SolverOptions {
        max_step: 0.05,
        first_step: 0.05,
        ..SolverOptions::default()
    };
    let mut observe = |s: &System| {
        vec![s.contributions[1]
            .tool_force([0.0, -1.0, 0.0])
            .unwrap_or(0.0)]
    };
    stepper::run(sys, &path, &opts, &mut observe, None).unwrap();
}

/// Dense global tangent from the sparse values.
fn dense(sys: &System) -> Vec<Vec<f64>> {
    let n = sys.dofs.equations;
    let mut k = vec![vec![0.0; n]; n];
    for c in 0..n {
        let (first, rows) = sys.pattern.column(c);
        for (i, &r) in rows.iter().enumerate() {
            k[r][c] = sys.values[first + i];
        }
    }
    k
}

#[test]
fn global_tangent_equals_finite_differences_of_the_global_residual() {
    let cases = [
        Case {
            kin: Kinematics::Axisymmetric,
            cell: CellType::Quad4,
            exact: true,
            friction: 0.3,
        },
        Case {
            kin: Kinematics::Axisymmetric,
            cell: CellType::Quad9,
            exact: false,
            friction: 50.0,
        },
        Case {
            kin: Kinematics::PlaneStrain { thickness: 2.0 },
            cell: CellType::Quad9,
            exact: true,
            friction: 0.2,
        },
        Case {
            kin: Kinematics::PlaneStrain { thickness: 2.0 },
            cell: CellType::Quad4,
            exact: false,
            friction: 50.0,
        },
        Case {
            kin: Kinematics::PlaneStress { thickness: 0.5 },
            cell: CellType::Quad4,
            exact: true,
            friction: 0.2,
        },
        Case {
            kin: Kinematics::PlaneStress { thickness: 0.5 },
            cell: CellType::Quad9,
            exact: false,
            friction: 0.0,
        },
        Case {
            kin: Kinematics::ThreeD,
            cell: CellType::Hex8,
            exact: true,
            friction: 0.0,
        },
        Case {
            kin: Kinematics::ThreeD,
            cell: CellType::Hex8,
            exact: false,
            friction: 0.0,
        },
        Case {
            kin: Kinematics::ThreeD,
            cell: CellType::Hex8,
            exact: true,
            friction: 0.2,
        },
        Case {
            kin: Kinematics::ThreeD,
            cell: CellType::Hex8,
            exact: false,
            friction: 50.0,
        },
        Case {
            kin: Kinematics::ThreeD,
            cell: CellType::Hex8,
            exact: false,
            friction: 0.5,
        },
        Case {
            kin: Kinematics::ThreeD,
            cell: CellType::Hex8,
            exact: true,
            friction: 50.0,
        },
    ];
    for c in &cases {
        let mut sys = system(c);
        pressed(&mut sys, 0.1);
        let tool = sys.part::<RigidContact>(1).unwrap();
        assert!(tool.active() > 0, "{:?} {:?}: no contact", c.kin, c.cell);
        // an unconverged state off the path: perturb every unknown
        let target = target(&sys, &[0.23, 0.12]);
        sys.prescribe(&target);
        for (k, u) in sys.u.iter_mut().enumerate() {
            if sys.dofs.equation(k) != NONE {
                *u += 1e-3 * ((k as f64) * 0.7).sin();
            }
        }
        sys.assemble(&target, true).unwrap();
        if c.kin == Kinematics::ThreeD && c.friction > 0.0 {
            // both regimes of the 3D return map: mu = 50 sticks everywhere,
            // mu = 0.2 slides, mu = 0.5 has points in both
            let tool = sys.part::<RigidContact>(1).unwrap();
            let (a, s) = (tool.active(), tool.slipping());
            let mixed = if c.friction > 1.0 {
                s == 0
            } else if c.friction < 0.3 {
                s > 0
            } else {
                s > 0 && s < a
            };
            assert!(mixed, "friction {}: {s} of {a} sliding", c.friction);
        }
        let k = dense(&sys);
        let scale = k.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        let h = 1e-7;
        let n = sys.dofs.equations;
        let free: Vec<usize> = (0..sys.u.len())
            .filter(|&s| sys.dofs.equation(s) != NONE)
            .collect();
        let mut worst = 0.0f64;
        for &s in &free {
            let e = sys.dofs.equation(s);
            let u0 = sys.u[s];
            sys.u[s] = u0 + h;
            sys.assemble(&target, false).unwrap();
            let rp = sys.residual.clone();
            sys.u[s] = u0 - h;
            sys.assemble(&target, false).unwrap();
            let rm = sys.residual.clone();
            sys.u[s] = u0;
            for r in 0..n {
                let fd = (rp[r] - rm[r]) / (2.0 * h);
                worst = worst.max((fd - k[r][e]).abs() / scale);
            }
        }
        assert!(
            worst < 1e-6,
            "{:?} {:?} exact {} friction {}: worst {worst:.2e}",
            c.kin,
            c.cell,
            c.exact,
            c.friction
        );
    }
}

/// A failed attempt (with augmentations changing the contact multipliers,
/// then an assembly failure) followed by a rollback leaves the system
/// exactly where a run that never failed is: the retried increment gives
/// bit-identical state and forces.
#[test]
fn rollback_restores_contact_history_exactly() {
    let c = Case {
        kin: Kinematics::Axisymmetric,
        cell: CellType::Quad4,
        exact: true,
        friction: 0.3,
    };
    let opts = SolverOptions {
        max_augmentations: 5,
        ..SolverOptions::default()
    };
    let mut a = system(&c);
    pressed(&mut a, 0.0);
    let next = target(&a, &[0.3, 0.0]);
    a.solve_increment(&next, &opts).unwrap();
    a.commit(&next);
    // b: an attempt at a larger step that augments the multipliers and
    // then fails (the first failure point after an augmentation)
    let big = target(&a, &[0.45, 0.0]);
    let mut b = None;
    for n in (4..400).step_by(4) {
        let mut s = system(&c);
        pressed(&mut s, 0.0);
        let aug0 = s.stats.augmentations;
        s.fail_after = Some(n);
        let u_c = s.u.clone();
        if s.solve_increment(&big, &opts).is_err() && s.stats.augmentations > aug0 {
            s.u.clone_from(&u_c);
            s.fail_after = None;
            b = Some(s);
            break;
        }
    }
    let mut b = b.expect("an attempt that augments and then fails");
    b.rollback();
    b.solve_increment(&next, &opts).unwrap();
    b.commit(&next);
    assert_eq!(a.u, b.u, "state after the retry");
    let fa = a.contributions[1].tool_force([0.0, -1.0, 0.0]).unwrap();
    let fb = b.contributions[1].tool_force([0.0, -1.0, 0.0]).unwrap();
    assert_eq!(fa.to_bits(), fb.to_bits());
}

/// A neo-Hookean whose modulus grows with the largest `I1b - 3` reached so
/// far: `P = (1 + beta m_old) P_NH`, `m_new = max(m_old, I1b - 3)`. A
/// stand-in for any material with history (viscoelastic internal
/// variables use the same path).
struct Hardening {
    c10: f64,
    beta: f64,
}

impl crate::material::PointMaterial for Hardening {
    fn iso_stress_tangent(&self, f: &nalgebra::Matrix3<f64>) -> crate::material::StressTangent9 {
        NeoHookeanIso { c10: self.c10 }.iso_stress_tangent(f)
    }
    fn shear_modulus(&self) -> f64 {
        2.0 * self.c10
    }
    fn history_len(&self) -> usize {
        1
    }
    fn stress_tangent_with_history(
        &self,
        f: &nalgebra::Matrix3<f64>,
        _dt: f64,
        old: &[f64],
    ) -> crate::material::StressTangent9 {
        let (p, a) = self.iso_stress_tangent(f);
        let s = 1.0 + self.beta * old[0];
        (p * s, a * s)
    }
    fn update_history(&self, f: &nalgebra::Matrix3<f64>, _dt: f64, old: &[f64], new: &mut [f64]) {
        let j = f.determinant();
        new[0] = old[0].max(j.powf(-2.0 / 3.0) * f.norm_squared() - 3.0);
    }
}

/// A 2 x 2 plane-strain block of the hardening material, bottom and left
/// side held normally, the top pressed by channel 0.
fn hardening_block(beta: f64) -> System {
    block(Arc::new(Hardening { c10: 0.5, beta }), Volumetric::D1(0.1))
}

/// The 2 x 2 plane-strain block of `hardening_block` with any material.
fn block(material: Arc<dyn crate::material::PointMaterial>, volumetric: Volumetric) -> System {
    let mesh = Mesh::graded_rectangle(2.0, 2.0, Grading::uniform(2.0, 2), Grading::uniform(2.0, 2))
        .unwrap();
    let kin = Kinematics::PlaneStrain { thickness: 1.0 };
    let mut body = SolidBody::new(
        "body",
        &mesh,
        &["body"],
        kernel_for(CellType::Quad4, kin, PressureSpace::P0).unwrap(),
        volumetric == Volumetric::Incompressible,
    )
    .unwrap();
    body.set_material(
        "body",
        RegionMaterial {
            material,
            volumetric,
        },
    )
    .unwrap();
    let bcs = [
        Dirichlet::fixed("axis", 0),
        Dirichlet::fixed("bottom", 1),
        Dirichlet::driven("top", 1, 0, -1.0),
    ];
    let mut sys = System::new(mesh, 2, vec![Box::new(body)], &bcs, 1).unwrap();
    sys.force_floor = 1e-6;
    sys
}

fn force_at_end(sys: &mut System, drive: &[f64]) -> f64 {
    let mut observe = |s: &System| vec![s.channel_reaction(0)];
    let out = stepper::run(
        sys,
        &LoadPath::from_drive(drive),
        &SolverOptions::default(),
        &mut observe,
        None,
    )
    .unwrap();
    out.last().unwrap()[0]
}

/// The committed history is carried from increment to increment and used:
/// after pressing to 0.6 mm and back to 0.2 mm the block is stiffer at
/// 0.2 mm than when pressed to 0.2 mm directly; without hardening the two
/// agree (the path does not matter for an elastic material).
#[test]
fn material_history_is_committed_and_used() {
    let loaded = force_at_end(&mut hardening_block(5.0), &[0.6, 0.2]);
    let direct = force_at_end(&mut hardening_block(5.0), &[0.2]);
    assert!(loaded > 1.05 * direct, "{loaded} vs {direct}");
    let loaded = force_at_end(&mut hardening_block(0.0), &[0.6, 0.2]);
    let direct = force_at_end(&mut hardening_block(0.0), &[0.2]);
    assert!(
        (loaded - direct).abs() < 1e-8 * direct.abs(),
        "{loaded} vs {direct}"
    );
}

/// A failed attempt (whose assemblies wrote trial history), rolled back,
/// retries bit-identically to a run that never failed.
#[test]
fn rollback_restores_material_history_exactly() {
    let opts = SolverOptions::default();
    let mut observe = |s: &System| vec![s.channel_reaction(0)];
    let mut a = hardening_block(5.0);
    let mut b = hardening_block(5.0);
    stepper::run(
        &mut a,
        &LoadPath::from_drive(&[0.3]),
        &opts,
        &mut observe,
        None,
    )
    .unwrap();
    stepper::run(
        &mut b,
        &LoadPath::from_drive(&[0.3]),
        &opts,
        &mut observe,
        None,
    )
    .unwrap();
    let next = Target {
        channels: vec![0.5],
        time: 0.0,
        dt: 0.0,
    };
    a.solve_increment(&next, &opts).unwrap();
    a.commit(&next);
    let u_c = b.u.clone();
    b.fail_after = Some(1);
    let big = Target {
        channels: vec![0.9],
        time: 0.0,
        dt: 0.0,
    };
    assert!(b.solve_increment(&big, &opts).is_err());
    b.fail_after = None;
    b.u.clone_from(&u_c);
    b.rollback();
    b.solve_increment(&next, &opts).unwrap();
    b.commit(&next);
    assert_eq!(a.u, b.u);
    assert_eq!(
        a.channel_reaction(0).to_bits(),
        b.channel_reaction(0).to_bits()
    );
}

/// A hook after the converged increment (the sensitivities' perturbed
/// assemblies) that fails recoverably, as an element inverted at a
/// perturbed state, on increments over 0.1 mm: the stepper cuts and
/// retries as it does for Newton's failures, and reaches the force of a run
/// without the hook; a hook that always fails stops the run after the
/// cuts, with the outputs of the stations that converged.
#[test]
fn a_recoverable_failure_of_the_increment_hook_cuts_the_step() {
    let opts = SolverOptions {
        first_step: 0.3,
        max_step: 0.3,
        ..SolverOptions::default()
    };
    let path = LoadPath::from_drive(&[0.3, 0.6]);
    let mut observe = |s: &System| vec![s.channel_reaction(0)];
    let mut plain = hardening_block(0.0);
    let without = stepper::run(&mut plain, &path, &opts, &mut observe, None).unwrap();
    let mut sys = hardening_block(0.0);
    let mut calls = 0;
    let mut hook = |s: &mut System, t: &Target| {
        calls += 1;
        let increment = (t.channels[0] - s.committed.channels[0]).abs();
        if increment > 0.1 {
            Err(FeError::InvertedElement {
                element: 0,
                det_f: -0.5,
            })
        } else {
            Ok(())
        }
    };
    let with = stepper::run_with_hook(&mut sys, &path, &opts, &mut observe, None, Some(&mut hook))
        .unwrap();
    assert!(sys.stats.cuts >= 2, "{:?}", sys.stats);
    assert!(calls > sys.stats.increments, "{calls} {:?}", sys.stats);
    for (a, b) in with.iter().zip(&without) {
        assert!((a[0] - b[0]).abs() < 1e-6 * b[0].abs(), "{a:?} vs {b:?}");
    }
    // a hook that always fails: the cuts, then the error and no station
    let mut sys = hardening_block(0.0);
    let mut always = |_: &mut System, _: &Target| -> Result<(), FeError> {
        Err(FeError::InvertedElement {
            element: 3,
            det_f: -0.1,
        })
    };
    let failed = stepper::run_with_hook(
        &mut sys,
        &path,
        &opts,
        &mut observe,
        None,
        Some(&mut always),
    )
    .unwrap_err();
    assert_eq!(failed.cuts, opts.max_cuts);
    assert!(matches!(
        failed.error,
        FeError::InvertedElement { element: 3, .. }
    ));
    assert!(failed.completed.is_empty() && failed.sample == 0);
}

/// A plane-strain block under a wheel pressed by channel 0 and moved along
/// +x by channel 1, rolling without slip (`rolling`) or sliding; returns
/// the (horizontal, vertical) force on the wheel at the end.
fn wheel_forces(rolling: bool, friction: f64) -> (f64, f64) {
    let mesh = Mesh::graded_rectangle(
        8.0,
        2.0,
        Grading::uniform(8.0, 16),
        Grading::uniform(2.0, 4),
    )
    .unwrap();
    let kin = Kinematics::PlaneStrain { thickness: 1.0 };
    let mut body = SolidBody::new(
        "body",
        &mesh,
        &["body"],
        kernel_for(CellType::Quad4, kin, PressureSpace::P0).unwrap(),
        true,
    )
    .unwrap();
    body.set_material(
        "body",
        RegionMaterial {
            material: Arc::new(NeoHookeanIso { c10: 0.5 }),
            volumetric: Volumetric::Incompressible,
        },
    )
    .unwrap();
    let (origin, press, travel) = ([2.0, 2.0, 0.0], (0, [0.0, -1.0, 0.0]), (1, [1.0, 0.0, 0.0]));
    let motion = if rolling {
        ToolMotion::rolling(origin, press, travel, 1.5, 2)
    } else {
        ToolMotion::translating(origin, vec![press, travel])
    };
    let contact = RigidContact::new(
        "wheel",
        Box::new(Wheel2d { radius: 1.5 }),
        motion,
        &mesh,
        "top",
        kin,
        ContactOptions {
            friction,
            penalty_normal: 50.0,
            penalty_tangent: 50.0,
            penetration_tol: 1e-6,
            points: ContactPoints::EdgeGauss,
        },
        2,
    )
    .unwrap();
    let bcs = [Dirichlet::fixed("bottom", 0), Dirichlet::fixed("bottom", 1)];
    let mut sys = System::new(mesh, 2, vec![Box::new(body), Box::new(contact)], &bcs, 2).unwrap();
    sys.force_floor = 1e-6;
    let path = LoadPath {
        tau: vec![0.15, 2.15],
        values: vec![vec![0.15, 0.0], vec![0.15, 2.0]],
        time: vec![0.0; 2],
    };
    let opts = SolverOptions {
        max_step: 0.05,
        first_step: 0.05,
        ..SolverOptions::default()
    };
    let mut observe = |s: &System| {
        let c = &s.contributions[1];
        vec![
            c.tool_force([1.0, 0.0, 0.0]).unwrap_or(0.0),
            c.tool_force([0.0, -1.0, 0.0]).unwrap_or(0.0),
        ]
    };
    let out = stepper::run(&mut sys, &path, &opts, &mut observe, None).unwrap();
    let last = out.last().unwrap();
    (last[0], last[1])
}

/// The wheel's stick points are carried in its own (rotating) frame: a
/// wheel that rolls without slip drags the surface much less than the same
/// wheel sliding, which reaches the Coulomb limit `|F_x| = mu F_y`; both
/// are reported on any axis while the wheel travels horizontally.
#[test]
fn rolling_wheel_carries_its_stick_points_and_reports_both_forces() {
    let mu = 0.4;
    let (fx_slide, fy_slide) = wheel_forces(false, mu);
    let (fx_roll, fy_roll) = wheel_forces(true, mu);
    assert!(fy_slide > 0.0 && fy_roll > 0.0);
    // sliding: the wheel drags the surface along +x at the Coulomb limit
    assert!(
        (fx_slide / fy_slide - mu).abs() < 0.05 * mu,
        "sliding: F_x / F_y = {}",
        fx_slide / fy_slide
    );
    // rolling: the stick points move with the wheel, the contact sticks
    // (partly) and the traction stays well inside the Coulomb limit; what
    // remains is the creep of a wheel turned at v / R over a surface that
    // the dent compresses
    assert!(
        fx_roll.abs() < 0.6 * mu * fy_roll,
        "rolling slides like sliding: F_x / F_y = {}",
        fx_roll / fy_roll
    );
    // frictionless: no horizontal force beyond the asymmetry of the dent
    let (fx0, fy0) = wheel_forces(false, 0.0);
    assert!(
        fx0.abs() < 0.1 * mu * fy0 && fy0 > 0.0,
        "frictionless F_x / F_y = {}",
        fx0 / fy0
    );
}

/// A material whose stress grows with the time it has spent loaded
/// (`P = (1 + beta t_loaded) P_NH`, history: the accumulated time): holds
/// must advance in time and hand `dt` to the material.
struct Aging {
    c10: f64,
    beta: f64,
}

impl crate::material::PointMaterial for Aging {
    fn iso_stress_tangent(&self, f: &nalgebra::Matrix3<f64>) -> crate::material::StressTangent9 {
        NeoHookeanIso { c10: self.c10 }.iso_stress_tangent(f)
    }
    fn shear_modulus(&self) -> f64 {
        2.0 * self.c10
    }
    fn history_len(&self) -> usize {
        1
    }
    fn stress_tangent_with_history(
        &self,
        f: &nalgebra::Matrix3<f64>,
        dt: f64,
        old: &[f64],
    ) -> crate::material::StressTangent9 {
        let (p, a) = self.iso_stress_tangent(f);
        let s = 1.0 + self.beta * (old[0] + dt);
        (p * s, a * s)
    }
    fn update_history(&self, _f: &nalgebra::Matrix3<f64>, dt: f64, old: &[f64], new: &mut [f64]) {
        new[0] = old[0] + dt;
    }
}

fn aging_force(max_time_step: Option<f64>) -> (Vec<f64>, usize) {
    // exactly incompressible: the pressure scales with the deviatoric
    // stress, so the displacement field does not change over the hold and
    // the force follows the aging factor exactly
    let mut sys = block(
        Arc::new(Aging {
            c10: 0.5,
            beta: 0.5,
        }),
        Volumetric::Incompressible,
    );
    // ramp to 0.2 mm in 1 s, hold 1 s
    let time = [0.5, 1.0, 1.5, 2.0];
    let drive = [0.1, 0.2, 0.2, 0.2];
    let opts = SolverOptions {
        max_time_step,
        ..SolverOptions::default()
    };
    let path = LoadPath::from_loading(&drive, Some(&time), opts.max_step, max_time_step);
    let mut observe = |s: &System| vec![s.channel_reaction(0)];
    let out = stepper::run(&mut sys, &path, &opts, &mut observe, None).unwrap();
    (out.iter().map(|o| o[0]).collect(), sys.stats.increments)
}

/// A hold at constant drive advances time in increments of at most
/// `max_time_step` and the material sees `dt`: the aging block's force
/// grows by the factor (1 + beta t) over the hold. Without a time step,
/// the hold costs no increment (rate-independent use).
#[test]
fn holds_advance_time_and_hand_dt_to_the_material() {
    let (f, increments) = aging_force(Some(0.1));
    assert!(
        increments >= 20,
        "{increments} increments for 2 s in steps of 0.1 s"
    );
    // force at the end of the hold / at its start = (1 + 0.5 * 2) / (1 + 0.5 * 1)
    let ratio = f[3] / f[1];
    assert!((ratio - 2.0 / 1.5).abs() < 1e-6, "ratio {ratio}");
    let (g, _) = aging_force(None);
    assert_eq!(
        g[3].to_bits(),
        g[1].to_bits(),
        "a hold without a time step is free"
    );
}

/// A 8 x 3 x 2 box (half of a 8 x 6 x 2 box: symmetry plane y = 0, bottom
/// fixed; incompressible neo-Hookean, mu = 1 MPa) under a sphere of radius
/// 4 mm centred on the plane, pressed 0.15 mm by channel 0 and dragged
/// 1.2 mm along +x by channel 1; returns the (horizontal, vertical) force
/// on the body after the press, after 0.6 mm and after 1.2 mm of drag.
fn sphere_forces(friction: f64) -> Vec<(f64, f64)> {
    let fine = |h: f64, length: f64| Grading {
        h_fine: h,
        fine_length: length,
        growth: 1.5,
    };
    let mesh = Mesh::graded_box(
        8.0,
        3.0,
        2.0,
        Grading::uniform(8.0, 24),
        fine(0.25, 1.25),
        fine(0.25, 0.5),
    )
    .unwrap();
    let kin = Kinematics::ThreeD;
    let mut body = SolidBody::new(
        "body",
        &mesh,
        &["body"],
        kernel_for(CellType::Hex8, kin, PressureSpace::P0).unwrap(),
        true,
    )
    .unwrap();
    body.set_material(
        "body",
        RegionMaterial {
            material: Arc::new(NeoHookeanIso { c10: 0.5 }),
            volumetric: Volumetric::Incompressible,
        },
    )
    .unwrap();
    let motion = ToolMotion::translating(
        [2.0, 0.0, 2.0],
        vec![(0, [0.0, 0.0, -1.0]), (1, [1.0, 0.0, 0.0])],
    );
    let contact = RigidContact::new(
        "sphere",
        Box::new(Revolution3d(ToolShape::Sphere { radius: 4.0 })),
        motion,
        &mesh,
        "top",
        kin,
        ContactOptions {
            friction,
            penalty_normal: 500.0,
            penalty_tangent: 500.0,
            penetration_tol: 1e-3,
            points: ContactPoints::EdgeGauss,
        },
        2,
    )
    .unwrap();
    let mut bcs: Vec<Dirichlet> = (0..3).map(|k| Dirichlet::fixed("bottom", k)).collect();
    bcs.push(Dirichlet::fixed("y0", 1));
    let mut sys = System::new(mesh, 3, vec![Box::new(body), Box::new(contact)], &bcs, 2).unwrap();
    sys.force_floor = 1e-6;
    let depth = 0.15;
    let path = LoadPath {
        tau: vec![depth, depth + 0.6, depth + 1.2],
        values: vec![vec![depth, 0.0], vec![depth, 0.6], vec![depth, 1.2]],
        time: vec![0.0; 3],
    };
    let opts = SolverOptions {
        max_step: 0.2,
        first_step: 0.05,
        ..SolverOptions::default()
    };
    let mut observe = |s: &System| {
        let c = &s.contributions[1];
        vec![
            c.tool_force([1.0, 0.0, 0.0]).unwrap_or(0.0),
            c.tool_force([0.0, 0.0, -1.0]).unwrap_or(0.0),
        ]
    };
    let out = stepper::run(&mut sys, &path, &opts, &mut observe, None).unwrap();
    out.iter().map(|o| (o[0], o[1])).collect()
}

/// A sphere dragged over a block with Coulomb friction (3D, two-component
/// slip) drags the surface along at the Coulomb limit, `F_x = mu F_z`, once
/// it slides; frictionless, there is no horizontal force. (What remains
/// above `mu F_z` is ploughing, the horizontal component of the normal
/// force on the dent tilted by the drag; it shrinks as the contact
/// flattens: +2.4 % here, and with penalties of 50 MPa/mm +8.7 % at
/// R = 2 mm, d = 0.25 mm, +2.3 % here, +1.1 % at R = 8 mm, d = 0.1 mm.)
/// Frictionless: the next test.
#[test]
fn sliding_sphere_drags_the_surface_at_the_coulomb_limit() {
    let mu = 0.3;
    let out = sphere_forces(mu);
    for &(fx, fz) in &out[1..] {
        assert!(fz > 0.0);
        assert!(
            (fx / fz - mu).abs() < 0.04 * mu,
            "sliding: F_x / F_z = {}",
            fx / fz
        );
    }
    // steady sliding: the same force after 0.6 and 1.2 mm
    assert!(
        (out[2].0 - out[1].0).abs() < 0.01 * out[2].0,
        "F_x {} then {}",
        out[1].0,
        out[2].0
    );
}

/// The same sphere frictionless: no horizontal force. (A test of its own
/// so that the two 3D runs, ~30 s each in the dev profile, run side by
/// side.)
#[test]
fn frictionless_sliding_sphere_has_no_horizontal_force() {
    let mu = 0.3;
    let out = sphere_forces(0.0);
    for (fx, fz) in &out {
        assert!(
            *fz > 0.0 && fx.abs() < 0.02 * mu * fz,
            "F_x / F_z = {}",
            fx / fz
        );
    }
}

/// Self-contact of a folded surface: the assembled tangent of
/// [`crate::self_contact::SelfContact`] equals central finite differences
/// of its residual (axisymmetric, two nodes pushed through non-adjacent,
/// tilted segments of the same top surface), and a node outside the
/// segment's span, or behind it deeper than `depth`, adds nothing.
#[test]
fn self_contact_tangent_equals_finite_differences() {
    use crate::self_contact::SelfContact;
    // one row of cells: every free node is on the top surface
    let mesh = Mesh::graded_rectangle(6.0, 1.0, Grading::uniform(6.0, 6), Grading::uniform(1.0, 1))
        .unwrap();
    let kin = Kinematics::Axisymmetric;
    let mut sc = SelfContact::new("top", &mesh, "top", kin, |_| true, 10.0).unwrap();
    sc.penalty = 3.0;
    sc.depth = 0.5;
    let top: Vec<usize> = mesh.node_set("top").unwrap().to_vec();
    let bcs = [Dirichlet::fixed("bottom", 0), Dirichlet::fixed("bottom", 1)];
    let mut sys = System::new(mesh, 2, vec![Box::new(sc)], &bcs, 0).unwrap();
    // top nodes at r = 0..6, z = 1: tilt segment (2, 3), push node 5 under
    // it and node 0 under segment (3, 4)
    let mut set = |n: usize, du: [f64; 2]| {
        sys.u[2 * top[n]] = du[0];
        sys.u[2 * top[n] + 1] = du[1];
    };
    set(2, [0.1, 0.15]);
    set(3, [-0.05, -0.1]);
    set(5, [-2.6, -0.3]);
    set(0, [3.4, -0.12]);
    set(4, [0.0, 0.05]);
    for (k, u) in sys.u.iter_mut().enumerate() {
        *u += 1e-3 * ((k as f64) * 0.7).sin();
    }
    let target = Target {
        channels: vec![],
        time: 0.0,
        dt: 0.0,
    };
    sys.assemble(&target, true).unwrap();
    let active = sys.part::<SelfContact>(0).unwrap().active();
    // the two pushed nodes, and nodes behind the segments the fold turned
    // over
    assert!(active >= 2, "{active} pairs in contact");
    let k = dense(&sys);
    let scale = k.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 0.0);
    let h = 1e-7;
    let n = sys.dofs.equations;
    let mut worst = 0.0f64;
    for s in 0..sys.u.len() {
        let e = sys.dofs.equation(s);
        if e == NONE {
            continue;
        }
        let u0 = sys.u[s];
        sys.u[s] = u0 + h;
        sys.assemble(&target, false).unwrap();
        let rp = sys.residual.clone();
        sys.u[s] = u0 - h;
        sys.assemble(&target, false).unwrap();
        let rm = sys.residual.clone();
        sys.u[s] = u0;
        for r in 0..n {
            let fd = (rp[r] - rm[r]) / (2.0 * h);
            worst = worst.max((fd - k[r][e]).abs() / scale);
        }
    }
    assert!(worst < 1e-6, "worst {worst:.2e}");
    // deeper than `depth`: nothing
    sys.part_mut::<SelfContact>(0).unwrap().depth = 0.05;
    sys.assemble(&target, true).unwrap();
    assert_eq!(sys.part::<SelfContact>(0).unwrap().active(), 0);
}

/// The handles [`Parts::add`] returns reach their contributions in the
/// built system whatever the order they were added in; a handle of another
/// system that points at a contribution of another type is an error naming
/// what is there.
#[test]
fn typed_handles_reach_their_contributions() {
    let mesh = Mesh::graded_rectangle(4.0, 2.0, Grading::uniform(4.0, 4), Grading::uniform(2.0, 2))
        .unwrap();
    let kin = Kinematics::Axisymmetric;
    let body = || {
        SolidBody::new(
            "body",
            &mesh,
            &["body"],
            kernel_for(CellType::Quad4, kin, PressureSpace::P0).unwrap(),
            true,
        )
        .unwrap()
    };
    let contact = RigidContact::new(
        "tool",
        Box::new(Profile2d(ToolShape::n1_needle())),
        ToolMotion::translating([0.0, 2.0, 0.0], vec![(0, [0.0, -1.0, 0.0])]),
        &mesh,
        "top",
        kin,
        ContactOptions {
            friction: 0.0,
            penalty_normal: 20.0,
            penalty_tangent: 20.0,
            penetration_tol: 1e-6,
            points: ContactPoints::EdgeGauss,
        },
        1,
    )
    .unwrap();
    let mut parts = Parts::new();
    let tool = parts.add(contact);
    let solid = parts.add(body());
    let bcs = [Dirichlet::fixed("axis", 0), Dirichlet::fixed("bottom", 1)];
    let mut sys = System::from_parts(mesh.clone(), 2, parts, &bcs, 1).unwrap();
    assert_eq!(
        sys.get(tool).map(|c| c.name()).as_deref(),
        Some("tool `tool`")
    );
    assert_eq!(
        sys.get(solid).map(|c| c.name()).as_deref(),
        Some("body `body`")
    );
    sys.get_mut(tool).unwrap().smoothing = 0.01;
    assert_eq!(sys.get(tool).unwrap().smoothing, 0.01);
    // the first part of another system is a body; here it is the tool
    let mut other = Parts::new();
    let foreign = other.add(body());
    assert!(sys.get(foreign).is_none());
    let err = sys.get_mut(foreign).err().unwrap().to_string();
    assert!(err.contains("is tool `tool`"), "{err}");
}
