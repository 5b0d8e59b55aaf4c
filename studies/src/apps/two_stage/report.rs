//! The Markdown report of a staged Q1 identification ([`crate::apps::two_stage`]):
//! one row per stage (iterations, FE runs, wall time, RMS, estimates), the
//! one-stage comparison, and the estimates with standard errors, profile
//! intervals and, given the truth, their errors.

use crate::apps::two_stage::{StageResult, TwoStageResult};

/// `theta` with its Prony pairs `(g_i, tau_i)` (the trailing parameters
/// named `g<i>`, `tau<i>_s`) in increasing `tau`, and whether that moved
/// any: the series is the same in any order, so a fit from another start
/// can land on the same terms under swapped labels (the one-stage fit on
/// the 5 mm record did), and the table compares like with like.
fn prony_by_tau(theta: &[f64], names: &[String]) -> (Vec<f64>, bool) {
    let terms = names.iter().filter(|n| n.starts_with("tau")).count();
    let first = theta.len().saturating_sub(2 * terms);
    if terms < 2 || names.len() != theta.len() || !names[first].starts_with('g') {
        return (theta.to_vec(), false);
    }
    let mut pairs: Vec<(f64, f64)> = theta[first..].chunks(2).map(|c| (c[0], c[1])).collect();
    let before = pairs.clone();
    pairs.sort_by(|a, b| a.1.total_cmp(&b.1));
    let mut out = theta[..first].to_vec();
    out.extend(pairs.iter().flat_map(|&(g, t)| [g, t]));
    (out, pairs != before)
}

/// A stage's LM iterations, each round's in brackets when there were
/// several.
fn iterations(s: &StageResult) -> String {
    if s.round_iterations.len() > 1 {
        let each: Vec<String> = s.round_iterations.iter().map(|i| i.to_string()).collect();
        format!("{} ({})", s.iterations, each.join(" + "))
    } else {
        s.iterations.to_string()
    }
}

/// The result as a Markdown report: one row per stage, the estimates with
/// standard errors and profile intervals, and, given the truth, the errors.
pub fn report(result: &TwoStageResult, truth: Option<&[f64]>) -> String {
    use std::fmt::Write;
    let mut r = String::new();
    let _ = writeln!(r, "record `{}`, model {}\n", result.record, result.model);
    if let Some(h) = result.correcting_mesh_mm {
        let _ = writeln!(
            r,
            "Each fit ran on the fit mesh's model corrected, sample by sample, to a mesh of {h} mm \
             under the punch at an anchor (output space mapping); the polish and the one-stage fit \
             moved the anchor to their estimate, round by round, until the estimates moved by less \
             than {} of their standard errors. LM iterations are summed over the rounds (each round's \
             in brackets); FE runs are the fit mesh's, the correcting mesh's runs are counted apart.\n",
            crate::apps::two_stage::ROUND_TOLERANCE
        );
        if let Some(rho) = result.fit_edge_radius_mm {
            let _ = writeln!(
                r,
                "The fit mesh's punch has an edge rounded {rho} mm (resolved by its cells, so that its \
                 force is smooth in the parameters); the correcting mesh's is the record's punch.\n"
            );
        }
    }
    let corrected = result.correcting_mesh_mm.is_some();
    let _ = writeln!(
        r,
        "| route | free | samples | LM iterations | FE runs |{} wall (s) | converged | RMS (N) | {} |",
        if corrected { " correcting-mesh runs |" } else { "" },
        result.names.join(" | ")
    );
    let _ = writeln!(
        r,
        "|{}",
        "---|".repeat(8 + usize::from(corrected) + result.names.len())
    );
    let row = |r: &mut String, s: &StageResult| {
        let (theta, reordered) = prony_by_tau(&s.theta, &result.names);
        let _ = writeln!(
            r,
            "| {}{} | {} | {} | {} | {} |{} {:.1} | {} | {:.3e} | {} |",
            s.stage,
            if reordered {
                " (its Prony terms swapped into tau order)"
            } else {
                ""
            },
            s.free.join(", "),
            s.samples,
            iterations(s),
            s.fe_runs,
            if corrected {
                format!(" {} |", s.mesh_corrections.len())
            } else {
                String::new()
            },
            s.wall_s,
            if s.converged {
                "yes"
            } else {
                s.termination.as_str()
            },
            s.fit.rms,
            theta
                .iter()
                .map(|v| format!("{v:.5}"))
                .collect::<Vec<_>>()
                .join(" | ")
        );
    };
    for s in &result.stages {
        row(&mut r, s);
    }
    let _ = writeln!(
        r,
        "| two-stage total | | | {} | {} |{} {:.1} | | | |",
        result.stages.iter().map(|s| s.iterations).sum::<u64>(),
        result.staged_fe_runs,
        if corrected {
            format!(
                " {} |",
                result
                    .stages
                    .iter()
                    .map(|s| s.mesh_corrections.len())
                    .sum::<usize>()
            )
        } else {
            String::new()
        },
        result.staged_wall_s
    );
    if let Some(s) = &result.one_stage {
        row(&mut r, s);
    }
    if let Some(t) = truth {
        let _ = writeln!(
            r,
            "| truth |{} {} |",
            " |".repeat(7 + usize::from(corrected)),
            t.iter()
                .map(|v| format!("{v:.5}"))
                .collect::<Vec<_>>()
                .join(" | ")
        );
    }
    for s in result.stages.iter().chain(&result.one_stage) {
        if !s.moved && !s.free.is_empty() {
            let _ = writeln!(
                r,
                "\n**{}: no LM step was accepted**: every trial step raised the SSE until the step \
                 test stopped LM where it started. Either the start is the optimum, or the FE model is \
                 not smooth in its parameters there (a run that takes another branch); its standard \
                 errors come from a finite-difference Jacobian that may have crossed such a jump. \
                 Compare with the other route.",
                s.stage
            );
        }
        if !s.settled {
            let _ = writeln!(
                r,
                "\n**{}: the correction rounds ran out before the anchor settled**: the last round \
                 moved an estimate by {:.1} standard errors from the anchor its correction was made \
                 at (the rounds stop below {}), so the estimate is not yet the correcting mesh's \
                 optimum. More rounds, or a start nearer the optimum (the staged route's), settle it.",
                s.stage,
                s.last_round_move_se,
                crate::apps::two_stage::ROUND_TOLERANCE
            );
        }
    }
    if let Some(c) = &result.mesh_check {
        r += &crate::apps::two_stage::mesh_check::report(
            c,
            &result.names,
            Some(result.correcting_mesh_mm.unwrap_or(result.fit_mesh_mm)),
        );
    }
    let polish = result.stages.last().expect("the polish");
    let _ =
        writeln!(
        r,
        "\n| parameter | estimate | standard error | 95 % profile interval | profile FE runs |{}",
        if truth.is_some() { " truth | error / SE |" } else { "" }
    );
    let _ = writeln!(
        r,
        "|---|---|---|---|---|{}",
        if truth.is_some() { "---|---|" } else { "" }
    );
    for (k, e) in polish.fit.parameters.iter().enumerate() {
        let prof = result.profiles.iter().find(|p| p.param == e.name);
        let side = |v: Option<f64>, what: &str| match v {
            Some(x) => format!("{x:.5}"),
            None => format!("not bounded {what}"),
        };
        let interval = prof.map_or("-".into(), |p| {
            format!("[{}, {}]", side(p.lower, "below"), side(p.upper, "above"))
        });
        let _ = write!(
            r,
            "| {} | {:.5} | {} | {} | {} |",
            e.name,
            e.value,
            e.standard_error.map_or("-".into(), |s| format!("{s:.2e}")),
            interval,
            prof.map_or(0, |p| p.fe_runs)
        );
        if let Some(t) = truth {
            let _ = write!(
                r,
                " {:.5} | {} |",
                t[k],
                e.standard_error
                    .map_or("-".into(), |s| format!("{:.2}", (e.value - t[k]) / s))
            );
        }
        let _ = writeln!(r);
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The one-stage fit of the 5 mm record: the same two terms as the
    /// staged fit under swapped labels; the table puts them in tau order.
    #[test]
    fn prony_terms_are_shown_in_tau_order() {
        let names: Vec<String> = ["C10", "g1", "tau1_s", "g2", "tau2_s"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let swapped = [0.00148, 0.20158, 9.13134, 0.33275, 0.30711];
        let (t, moved) = prony_by_tau(&swapped, &names);
        assert!(moved);
        assert_eq!(t, vec![0.00148, 0.33275, 0.30711, 0.20158, 9.13134]);
        let (t, moved) = prony_by_tau(&t, &names);
        assert!(!moved);
        assert_eq!(t[1], 0.33275);
        // one term, or a model without Prony terms: as given
        let one: Vec<String> = ["C10", "g1", "tau1_s"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        assert_eq!(
            prony_by_tau(&[1.0, 0.3, 5.0], &one),
            (vec![1.0, 0.3, 5.0], false)
        );
        assert_eq!(prony_by_tau(&[1.0], &names[..1]), (vec![1.0], false));
    }
}
