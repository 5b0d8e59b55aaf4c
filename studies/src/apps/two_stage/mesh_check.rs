//! How far a staged Q1 identification's estimates ([`crate::apps::two_stage`])
//! would move on another mesh: the discretisation error of the estimates,
//! which their standard errors (noise only) do not hold.
//!
//! After the polish, the polish is refitted with its fit mesh's model
//! corrected to the check mesh instead (`palpate_inverse::FidelityCorrection`,
//! output space mapping, theory.md 5.9), from the polish's estimate `theta`
//! and round by round as the polish, until the estimates move by less than
//! 0.1 SE: the check mesh's output-space-mapping fixed point, as the
//! polish's estimate is the correcting mesh's. Its first round takes, to
//! first order, the Gauss-Newton step to the check mesh's optimum
//!
//! ```text
//! delta = -(J^T J)^-1 J^T (F_c(theta) - F_h(theta)),
//! ```
//!
//! the least-squares image of the two meshes' force difference (`F_h` the
//! mesh the estimate is of, `F_c` the check mesh; e.g. Bates & Watts 1988,
//! *Nonlinear regression analysis*, ch. 2), with `J` the fit mesh's
//! sensitivities scaled to the check mesh's forces. Each round costs one
//! run of the check mesh and one LM of the fit mesh. A shift of more than a
//! standard error says the estimate is limited by the mesh, not by the
//! noise. It is read through the fit mesh's sensitivities: where their
//! shape differs from the check mesh's (a fit mesh with its own punch edge,
//! at depth), the fixed point is not the check mesh's own optimum (5 mm
//! record, tau1: docs/validation/two-stage.md).

use crate::apps::two_stage::{say_round, stage_result, Q1Record, Say, TwoStageOptions};
use palpate_inverse::staged::{self, Shift, Stage, StageModels};
use serde::Serialize;
use std::sync::Arc;

/// The estimates on the check mesh against the polish's.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeshCheck {
    /// Element size under the punch of the check mesh (mm).
    pub mesh_mm: f64,
    /// LM iterations over the corrected rounds.
    pub iterations: u64,
    /// Rounds (runs of the check mesh), whether the last moved the
    /// estimates by less than the tolerance, and its largest move in SE.
    pub rounds: usize,
    pub settled: bool,
    pub last_round_move_se: f64,
    /// Fit-mesh runs, wall time (the check mesh's runs included), the last
    /// round's RMS (N) and whether its LM converged.
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

/// The mesh check of an estimate `theta` of the whole `record` with
/// standard errors `se` (the polish's): the fit mesh's model corrected to
/// the check mesh (`options.check_h`), from `theta`, round by round as the
/// polish (at most `options.correction_rounds`, until the estimates move by
/// less than [`crate::apps::two_stage::ROUND_TOLERANCE`] SE).
pub fn check_estimate(
    record: &Q1Record,
    options: &TwoStageOptions,
    theta: &[f64],
    se: &[Option<f64>],
    say: Say<'_>,
) -> anyhow::Result<MeshCheck> {
    let h = options
        .check_h
        .ok_or_else(|| anyhow::anyhow!("a mesh check needs the check mesh's element size"))?;
    let models = StageModels {
        coarse: Arc::new(options.viscoelastic_model()),
        fine: Some(Arc::new(options.viscoelastic_model_at(h))),
    };
    let data = Stage {
        stage: "mesh-check".into(),
        set: record.name.clone(),
        loading: record.loading(),
        observed: record.force.clone(),
        fixed: Vec::new(),
    };
    let (out, _) = staged::check_estimate(
        &data,
        &models,
        theta,
        se,
        options.correction_rounds,
        &options.stage_options(),
        &mut say_round(say),
    )
    .map_err(|e| anyhow::anyhow!("mesh-check: {e}"))?;
    let (round, _) = stage_result("mesh-check", out);
    let mut check = compare(h, &round.theta, theta, se);
    check.iterations = round.iterations;
    check.rounds = round.mesh_corrections.len();
    check.fit_mesh_runs = round.fe_runs.saturating_sub(check.rounds);
    check.wall_s = round.wall_s;
    check.rms = round.fit.rms;
    check.converged = round.converged;
    check.settled = round.settled;
    check.last_round_move_se = round.last_round_move_se;
    Ok(check)
}

/// The shifts of the estimates `theta` from the polish's `polish`, in its
/// standard errors `se`.
fn compare(h: f64, theta: &[f64], polish: &[f64], se: &[Option<f64>]) -> MeshCheck {
    let Shift {
        theta,
        shift,
        shift_se,
    } = Shift::new(theta, polish, se);
    MeshCheck {
        mesh_mm: h,
        iterations: 0,
        rounds: 0,
        settled: true,
        last_round_move_se: 0.0,
        fit_mesh_runs: 0,
        wall_s: 0.0,
        rms: f64::NAN,
        converged: true,
        theta,
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
        "\n**Mesh check**: the polish refitted with its model corrected to a mesh of {} mm under \
         the punch instead{}, from the polish estimate, round by round as the polish ({} round{}{}; \
         {} LM iterations{}, {} fit-mesh runs, {:.1} s, RMS {:.3e} N). The shift is how far the \
         estimates move on that mesh, as seen through the fit mesh's sensitivities; a shift of a \
         standard error or more is the mesh's error in the estimates, which the standard errors do \
         not hold.\n",
        mm(check.mesh_mm),
        estimate_mesh.map_or(String::new(), |h| format!(" of {} mm", mm(h))),
        check.rounds,
        if check.rounds == 1 { "" } else { "s" },
        if check.settled {
            String::new()
        } else {
            format!(
                ", not settled: the last moved an estimate by {:.1} SE",
                check.last_round_move_se
            )
        },
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
        c.rounds = 2;
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
        assert!(md.contains("2 rounds;"), "{md}");
        c.settled = false;
        c.last_round_move_se = 0.7;
        let md = report(&c, &names, None);
        assert!(
            md.contains("not settled: the last moved an estimate by 0.7 SE"),
            "{md}"
        );
        assert_eq!(mm(0.2 / 3.0), "0.06667");
        assert_eq!(mm(0.5), "0.5");
    }
}
