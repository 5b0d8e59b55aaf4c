//! Every file in `studies/data/real` loads without editing and fits: the
//! test walks the directory, so a new file with no known test kind fails it.
//! Each record gets a neo-Hookean fit (one parameter, cheap); the timed VHB
//! records also a one-term QLV fit. The full comparison of laws is
//! `studies/real-data.toml` (docs/validation/real-data.md).

use palpate_inverse::ResidualKind;
use palpate_material::Law;
use palpate_studies::cli::calibrate::read_data;
use palpate_studies::model::calibration::{calibrate, parse_method, Request};
use palpate_studies::model::Viscous;
use palpate_studies::records::{TestData, TestKind};
use std::path::{Path, PathBuf};

fn real() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("data/real")
}

/// The `--data` option of a file, from its folder and name (the same
/// reading as `studies/real-data.toml`).
pub fn data_option(path: &Path) -> Option<String> {
    let name = path.file_stem()?.to_str()?;
    let dir = path.parent()?.file_name()?.to_str()?;
    let p = path.display();
    Some(match (dir, name) {
        ("brain_budday2017", n) if n.ends_with("_compression_tension") => format!("uniaxial={p}"),
        ("brain_budday2017", n) if n.ends_with("_simple_shear") => format!("simple_shear={p}"),
        ("brain_budday2017", n) if n.starts_with("extra_") => {
            // extra_corona_radiata_shear_at_axial_stretch_0d75 -> 0.75
            let s = n.rsplit('_').next()?.replace('d', ".");
            let a: f64 = s.parse().ok()?;
            format!("simple_shear[axial_stretch={a}]={p}")
        }
        ("kawabata1981", "biaxial") | ("meunier2008_silicone", "biaxial") => {
            format!("biaxial={p}")
        }
        ("meunier2008_silicone", "pure_shear") => format!("planar={p}"),
        ("meunier2008_silicone", "uniaxial") => format!("uniaxial={p}"),
        ("silicone_tensile_marechal", _) | ("vhb4910_zhao", _) => format!("uniaxial={p}"),
        _ => return None,
    })
}

fn fit(
    law: Law,
    data: &[TestData],
    viscous: Option<Viscous>,
) -> palpate_studies::model::calibration::Calibration {
    calibrate(Request {
        law,
        model: None,
        fitted: data,
        predict: &[],
        residual: ResidualKind::Absolute,
        method: parse_method("lm").unwrap(),
        fixed: Vec::new(),
        observer: None,
        viscous,
    })
    .unwrap_or_else(|e| panic!("{}: {e:#}", data[0].file))
}

#[test]
fn every_real_file_loads_and_fits() {
    let mut files = Vec::new();
    for dir in std::fs::read_dir(real()).unwrap() {
        let dir = dir.unwrap().path();
        if dir.is_dir() {
            for f in std::fs::read_dir(&dir).unwrap() {
                let f = f.unwrap().path();
                if f.extension().is_some_and(|e| e == "csv") {
                    files.push(f);
                }
            }
        }
    }
    files.sort();
    assert!(files.len() >= 40, "{} files", files.len());
    let mut kinds = std::collections::BTreeMap::new();
    for f in &files {
        let option =
            data_option(f).unwrap_or_else(|| panic!("{}: no test kind known", f.display()));
        let data = read_data(std::slice::from_ref(&option), None)
            .unwrap_or_else(|e| panic!("{option}: {e:#}"));
        let d = &data[0];
        *kinds.entry(format!("{:?}", d.test)).or_insert(0) += 1;
        let c = fit(Law::NeoHookean, &data, None);
        let c10 = c.params.get("C10").unwrap().value;
        assert!(
            c.converged && c10 > 0.0 && c10.is_finite(),
            "{option}: C10 {c10}"
        );
        // Neo-Hookean is a poor law for several of these (R^2 < 0.9 for the
        // strain-stiffening brain tension/compression asymmetry); a fit that
        // explains nothing would be a reading error.
        // Timed records (VHB relaxation at one stretch) are explained by the
        // viscous part only.
        if d.loading.time.is_some() {
            let v = fit(Law::NeoHookean, &data, Some(Viscous::Qlv(1)));
            assert!(v.sse <= c.sse, "{option}: QLV worse than elastic");
            assert!(v.r2 > 0.5, "{option}: QLV R^2 {}", v.r2);
        } else {
            assert!(c.r2 > 0.5, "{option}: neo-Hookean R^2 {}", c.r2);
        }
    }
    // Every kind is represented: uniaxial, general biaxial, equibiaxial, planar, simple shear.
    for k in [
        "Homogeneous(Uniaxial)",
        "GeneralBiaxial",
        "Homogeneous(Equibiaxial)",
        "Homogeneous(Planar)",
        "SimpleShear",
    ] {
        assert!(kinds.contains_key(k), "{k} missing: {kinds:?}");
    }
    assert_eq!(
        read_data(
            &[data_option(&real().join("kawabata1981/biaxial.csv")).unwrap()],
            None
        )
        .unwrap()[0]
            .test,
        TestKind::GeneralBiaxial
    );
}
