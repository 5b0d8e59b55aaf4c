//! How far a staged Q1 identification's estimates ([`crate::two_stage`])
//! would move on another mesh: the discretisation error of the estimates,
//! which their standard errors (noise only) do not hold.
//!
//! After the polish, one more round of it is corrected to the check mesh
//! instead (`palpate_inverse::FidelityCorrection` at the polish estimate
//! `theta`, output space mapping, theory.md 5.9) and refitted by LM from
//! `theta`. To first order that lands on the check mesh's own optimum: with
//! `F_h` the forces of the mesh the estimate is of and `F_c` the check
//! mesh's, the optimum moves by
//!
//! ```text
//! delta = -(J^T J)^-1 J^T (F_c(theta) - F_h(theta)),
//! ```
//!
//! the least-squares image of the force difference (a Gauss-Newton step,
//! e.g. Bates & Watts 1988, *Nonlinear regression analysis*, ch. 2), and
//! one corrected round takes that step with the fit mesh's sensitivities
//! scaled to the check mesh's forces. It costs one run of the check mesh
//! and one LM of the fit mesh. A shift of more than a standard error says
//! the estimate is limited by the mesh, not by the noise: at 5 mm with the
//! punch's 0.2 mm edge, tau1 (docs/guide.md, two-stage, session 22).

use crate::two_stage::{run_stage, Say, StageData, StageModels, StageResult, TwoStageOptions};
use palpate_core::ForwardModel;
use serde::Serialize;
use std::sync::Arc;

/// The estimates on the check mesh against the polish's.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeshCheck {
    /// Element size under the punch of the check mesh (mm).
    pub mesh_mm: f64,
    /// The corrected round: LM iterations, fit-mesh runs, wall time (the
    /// check mesh's run included), RMS (N), whether LM converged.
    pub iterations: u64,
    pub fit_mesh_runs: usize,
    pub wall_s: f64,
    pub rms: f64,
    pub converged: bool,
    /// Every parameter on the check mesh, in the model's order.
    pub theta: Vec<f64>,
    /// Check-mesh estimate minus the polish's.
    pub shift: Vec<f64>,
    /// The shift in the polish's standard errors (`None` where it has none).
    pub shift_se: Vec<Option<f64>>,
}

/// The mesh check of `polish` on `data` (the whole record): the fit mesh's
/// model `coarse` corrected to the check mesh at the polish's estimate.
pub(crate) fn mesh_check(
    data: &StageData<'_>,
    coarse: Arc<dyn ForwardModel>,
    polish: &StageResult,
    h: f64,
    options: &TwoStageOptions,
    say: Say<'_>,
) -> anyhow::Result<MeshCheck> {
    let models = StageModels {
        coarse,
        fine: Some(Arc::new(options.viscoelastic_model_at(h))),
    };
    let (round, _) = run_stage(data, &models, polish.theta.clone(), 1, options, say)?;
    let ses: Vec<Option<f64>> = polish
        .fit
        .parameters
        .iter()
        .map(|e| e.standard_error)
        .collect();
    let mut check = compare(h, &round.theta, &polish.theta, &ses);
    check.iterations = round.iterations;
    check.fit_mesh_runs = round.fe_runs.saturating_sub(round.mesh_corrections.len());
    check.wall_s = round.wall_s;
    check.rms = round.fit.rms;
    check.converged = round.converged;
    Ok(check)
}

/// The shifts of the estimates `theta` from the polish's `polish`, in its
/// standard errors `se`.
fn compare(h: f64, theta: &[f64], polish: &[f64], se: &[Option<f64>]) -> MeshCheck {
    let shift: Vec<f64> = theta.iter().zip(polish).map(|(c, p)| c - p).collect();
    let shift_se = se
        .iter()
        .zip(&shift)
        .map(|(s, d)| s.filter(|s| *s > 0.0).map(|s| d / s))
        .collect();
    MeshCheck {
        mesh_mm: h,
        iterations: 0,
        fit_mesh_runs: 0,
        wall_s: 0.0,
        rms: f64::NAN,
        converged: true,
        theta: theta.to_vec(),
        shift,
        shift_se,
    }
}

/// A mesh size to 4 significant digits (level 3, `0.2 / 3`, as 0.06667).
pub fn mm(h: f64) -> String {
    format!("{}", format!("{h:.3e}").parse::<f64>().unwrap_or(h))
}

/// The check as Markdown: what it is, and one row per parameter.
pub fn report(check: &MeshCheck, names: &[String], estimate_mesh: Option<f64>) -> String {
    use std::fmt::Write;
    let mut r = String::new();
    let _ = writeln!(
        r,
        "\n**Mesh check**: the polish refitted once more with its model corrected to a mesh of {} mm \
         under the punch instead{} at the polish estimate ({} LM iterations{}, {} fit-mesh runs and one \
         run of the check mesh, {:.1} s, RMS {:.3e} N). The shift is what the estimates would move \
         by on that mesh (to first order); a shift of a standard error or more is the mesh's error \
         in the estimate, which the standard errors do not hold.\n",
        mm(check.mesh_mm),
        estimate_mesh.map_or(String::new(), |h| format!(" of {h} mm")),
        check.iterations,
        if check.converged { "" } else { ", not converged" },
        check.fit_mesh_runs,
        check.wall_s,
        check.rms
    );
    let _ = writeln!(
        r,
        "| parameter | polish | on the {} mm mesh | shift | shift / SE |\n|---|---|---|---|---|",
        mm(check.mesh_mm)
    );
    for (k, name) in names.iter().enumerate() {
        let _ = writeln!(
            r,
            "| {name} | {:.5} | {:.5} | {:+.3e} | {} |",
            check.theta[k] - check.shift[k],
            check.theta[k],
            check.shift[k],
            check
                .shift_se
                .get(k)
                .copied()
                .flatten()
                .map_or("-".into(), |s| format!("{s:+.2}"))
        );
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shift is the check's estimate minus the polish's, in the
    /// polish's standard errors where it has them; the report gives each.
    #[test]
    fn the_shift_is_read_in_the_polishs_standard_errors() {
        let polish = [0.0016, 0.31, 0.41];
        let se = [Some(1e-5), None, Some(0.025)];
        let mut c = compare(0.0667, &[0.00159, 0.30, 0.50], &polish, &se);
        assert!((c.shift[2] - 0.09).abs() < 1e-12);
        assert!((c.shift_se[0].unwrap() + 1.0).abs() < 1e-9);
        assert_eq!(c.shift_se[1], None);
        assert!((c.shift_se[2].unwrap() - 3.6).abs() < 1e-9);
        c.fit_mesh_runs = 12;
        let names: Vec<String> = ["C10", "g1", "tau1_s"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let md = report(&c, &names, Some(0.1));
        assert!(md.contains("0.0667 mm") && md.contains("of 0.1 mm"), "{md}");
        assert!(
            md.contains("| tau1_s | 0.41000 | 0.50000 | +9.000e-2 | +3.60 |"),
            "{md}"
        );
        assert!(
            md.contains("| g1 | 0.31000 | 0.30000 | -1.000e-2 | - |"),
            "{md}"
        );
        assert!(md.contains("12 fit-mesh runs"), "{md}");
        assert_eq!(mm(0.2 / 3.0), "0.06667");
        assert_eq!(mm(0.5), "0.5");
    }
}
