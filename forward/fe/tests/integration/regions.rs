//! A stiff inclusion is data: a body over two mesh regions with a material
//! each (the Gmsh fixture `inclusion_quad9.msh`, 9-node plane-stress cells,
//! a wheel pressed on the top over the inclusion).

use std::sync::Arc;

use palpate_fe::body::{RegionMaterial, SolidBody};
use palpate_fe::contact::{ContactOptions, ContactPoints, RigidContact};
use palpate_fe::dofs::Dirichlet;
use palpate_fe::kernel::{kernel_for, PressureSpace};
use palpate_fe::kinematics::Kinematics;
use palpate_fe::material::NeoHookeanIso;
use palpate_fe::mesh::{CellType, Mesh};
use palpate_fe::motion::ToolMotion;
use palpate_fe::stepper::{self, LoadPath};
use palpate_fe::surface::Wheel2d;
use palpate_fe::{SolverOptions, System};
use palpate_material::Volumetric;

fn mesh() -> Mesh {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/inclusion_quad9.msh");
    Mesh::read_gmsh(&path).unwrap()
}

/// Wheel force (N, compression positive) at 0.3 mm with the given shear
/// moduli of the matrix and the inclusion; `split` puts the two regions in
/// one body with a material each, otherwise one material for both.
fn wheel_force(matrix: f64, inclusion: f64, split: bool) -> f64 {
    let mesh = mesh();
    let kin = Kinematics::PlaneStress { thickness: 1.0 };
    let kernel = kernel_for(CellType::Quad9, kin, PressureSpace::None).unwrap();
    let mut body = SolidBody::new("block", &mesh, &["matrix", "inclusion"], kernel, false).unwrap();
    let m = |c10: f64| RegionMaterial {
        material: Arc::new(NeoHookeanIso { c10 }),
        volumetric: Volumetric::Incompressible,
    };
    body.set_material("matrix", m(0.5 * matrix)).unwrap();
    body.set_material("inclusion", m(0.5 * if split { inclusion } else { matrix }))
        .unwrap();
    let contact = RigidContact::new(
        "wheel",
        Box::new(Wheel2d { radius: 4.0 }),
        ToolMotion::translating([5.0, 6.0, 0.0], vec![(0, [0.0, -1.0, 0.0])]),
        &mesh,
        "top",
        kin,
        ContactOptions {
            friction: 0.0,
            penalty_normal: 100.0 * matrix,
            penalty_tangent: 100.0 * matrix,
            penetration_tol: 1e-6,
            points: ContactPoints::EdgeGauss,
        },
        1,
    )
    .unwrap();
    let bcs = [Dirichlet::fixed("bottom", 0), Dirichlet::fixed("bottom", 1)];
    let mut sys = System::new(mesh, 2, vec![Box::new(body), Box::new(contact)], &bcs, 1).unwrap();
    sys.force_floor = 1e-9;
    let mut observe = |s: &System| {
        vec![s.contributions[1]
            .tool_force([0.0, -1.0, 0.0])
            .unwrap_or(0.0)]
    };
    let out = stepper::run(
        &mut sys,
        &LoadPath::from_drive(&[0.15, 0.3]),
        &SolverOptions::default(),
        &mut observe,
        None,
    )
    .unwrap();
    out[1][0]
}

#[test]
fn a_stiff_inclusion_is_a_region_with_another_material() {
    let homogeneous = wheel_force(1.0, 1.0, false);
    let same = wheel_force(1.0, 1.0, true);
    assert_eq!(
        homogeneous.to_bits(),
        same.to_bits(),
        "same material in both regions"
    );
    let stiff = wheel_force(1.0, 20.0, true);
    let soft = wheel_force(1.0, 0.05, true);
    assert!(homogeneous > 0.0);
    assert!(
        stiff > 1.05 * homogeneous,
        "stiff inclusion {stiff} vs {homogeneous}"
    );
    assert!(
        soft < 0.97 * homogeneous,
        "soft inclusion {soft} vs {homogeneous}"
    );
}
