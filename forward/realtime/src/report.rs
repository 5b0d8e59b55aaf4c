//! The held-out error table of a real-time model and the warning of a
//! build that misses its target, as `palpate realtime build` prints them
//! and `bench_realtime` writes them to docs/validation/realtime.md.

use crate::memory_kernel::MemoryKernel;
use crate::model::RealTimeModel;
use std::fmt::Write;

/// A warning naming the held-out histories whose largest error over their
/// peak is above `target` per cent (with the RMS error, which says whether
/// the history is off or a few stations are); none if all are within it.
pub fn target_warning(s: &RealTimeModel, target: f64) -> Option<String> {
    let over: Vec<String> = s
        .validation
        .iter()
        .filter(|h| 100.0 * h.max_relative_error > target)
        .map(|h| {
            let at = h
                .worst_at
                .map_or(String::new(), |(t, d)| format!(" at {t:.2} s, {d:.2} mm"));
            let rms = h
                .rms_relative_error
                .map_or(String::new(), |e| format!(", RMS {:.2} %", 100.0 * e));
            format!(
                "{} {:.2} %{at}{rms}",
                h.history,
                100.0 * h.max_relative_error
            )
        })
        .collect();
    if over.is_empty() {
        return None;
    }
    Some(format!(
        "warning: {} of {} held-out histories above the {target} % target (largest error over the peak): {}. The model is stored; at depth the largest errors sit where the contact ends or starts again (docs/validation/realtime.md)",
        over.len(),
        s.validation.len(),
        over.join("; ")
    ))
}

/// How the fitted memory meets the punch, in words.
pub fn contact_words(k: &MemoryKernel) -> String {
    let [g, a] = k.soft_contact;
    let contact = if !k.lift_off {
        "follows the punch".into()
    } else if g == 0.0 {
        "follows the free surface".into()
    } else {
        format!(
            "follows a surface that lets go over a gap of {g:.3} mm (compliant contact, press {a:.3e} N)"
        )
    };
    if k.stops.is_empty() {
        contact
    } else {
        let r: Vec<String> = k.stops.iter().map(|r| format!("{r:.3}")).collect();
        format!(
            "{contact}, with stop operators (hysteresis) of {} mm",
            r.join(", ")
        )
    }
}

/// The held-out error table (Markdown), with plain QLV's error beside the
/// fitted memory's when the model has one.
pub fn error_table(s: &RealTimeModel) -> String {
    let with_qlv = s.qlv_validation.len() == s.validation.len() && s.kernel.is_some();
    let mut r = String::new();
    if let Some(k) = &s.kernel {
        let _ = write!(
            r,
            "memory fitted to {} FE training histories ({} stations, RMS {:.3e} N); on loss of contact it {}",
            k.training.histories,
            k.training.stations,
            k.training.rms_n,
            contact_words(k),
        );
        if let Some([without, with]) = k.training.cv_max_relative_error {
            let _ = write!(
                r,
                " (cross-validated mean max error {:.2} % following the punch, {:.2} % the best loss of contact",
                100.0 * without,
                100.0 * with
            );
            for ([g, a], e) in &k.training.cv_contacts {
                let _ = if *g == 0.0 {
                    write!(r, "; hard {:.2} %", 100.0 * e)
                } else {
                    write!(r, "; gap {g} D, press {a} peak {:.2} %", 100.0 * e)
                };
            }
            if !k.training.cv_stops.is_empty() {
                let e: Vec<String> = k
                    .training
                    .cv_stops
                    .iter()
                    .map(|e| format!("{:.2}", 100.0 * e))
                    .collect();
                let _ = write!(
                    r,
                    "; with stop operators, the same forms in order: {} %",
                    e.join(" / ")
                );
            }
            r.push(')');
        }
        r.push_str("\n\n");
    }
    for f in &s.training_failures {
        let _ = writeln!(r, "left out of the fit: {f}\n");
    }
    for f in &s.validation_failures {
        let _ = writeln!(r, "not in the error table: {f}\n");
    }
    r.push_str(
        "| held-out FE history | stations | peak force (N) | max error (N) | max error / peak | where (s, mm) | RMS error / peak |",
    );
    r.push_str(if with_qlv {
        " plain QLV: max error / peak |\n|---|---|---|---|---|---|---|---|\n"
    } else {
        "\n|---|---|---|---|---|---|---|\n"
    });
    for (j, h) in s.validation.iter().enumerate() {
        let _ = write!(
            r,
            "| {} | {} | {:.4e} | {:.3e} | {:.2} % | {} | {} |",
            h.history,
            h.samples,
            h.peak_force_n,
            h.max_abs_error_n,
            100.0 * h.max_relative_error,
            h.worst_at
                .map_or("-".to_string(), |(t, d)| format!("{t:.2}, {d:.2}")),
            h.rms_relative_error
                .map_or("-".to_string(), |e| format!("{:.2} %", 100.0 * e))
        );
        if with_qlv {
            let _ = write!(
                r,
                " {:.2} % |",
                100.0 * s.qlv_validation[j].max_relative_error
            );
        }
        r.push('\n');
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{HistoryError, MonotoneCubic};

    fn row(name: &str, max: f64, rms: Option<f64>) -> HistoryError {
        HistoryError {
            history: name.into(),
            samples: 20,
            peak_force_n: 0.1,
            max_abs_error_n: 0.1 * max,
            max_relative_error: max,
            rms_relative_error: rms,
            worst_at: Some((13.8, 1.61)),
        }
    }

    /// The warning names exactly the held-out histories over the target,
    /// with where and the RMS; none when all are within it.
    #[test]
    fn the_build_warns_of_the_histories_over_the_target() {
        let curve = MonotoneCubic::new(vec![0.0, 0.5, 1.0], vec![0.0, 0.01, 0.03]).unwrap();
        let mut s = RealTimeModel::new("test".into(), curve, vec![(0.3, 0.5)]).unwrap();
        s.validation = vec![
            row("random 1", 0.012, Some(0.004)),
            row("random 3", 0.0381, Some(0.0103)),
            row("random 4", 0.025, None),
        ];
        let w = target_warning(&s, 2.0).expect("two over 2 %");
        assert!(
            w.starts_with("warning: 2 of 3 held-out histories above the 2 % target"),
            "{w}"
        );
        assert!(
            w.contains("random 3 3.81 % at 13.80 s, 1.61 mm, RMS 1.03 %"),
            "{w}"
        );
        assert!(w.contains("random 4 2.50 % at 13.80 s, 1.61 mm"), "{w}");
        assert!(!w.contains("random 1"), "{w}");
        assert_eq!(target_warning(&s, 4.0), None);
    }
}
