//! The plots of a factorial analysis (`palpate anova` and the manifests'
//! `anova` step): a Pareto chart of the standardised effects and the main
//! effects.

use super::plot::{grid_svg, Plot, Series, Style};
use palpate_uq::anova::Analysis;
use palpate_uq::stats::blom_scores;

/// The SVG plots of an analysis: (file name, SVG).
pub fn plots(a: &Analysis) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let t = &a.table;
    if let Some(p) = &a.pareto {
        let n = p.effects.len();
        let names: Vec<String> = p.effects.iter().rev().map(|e| e.term.clone()).collect();
        let y: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let x: Vec<f64> = p
            .effects
            .iter()
            .rev()
            .map(|e| e.standardised.abs())
            .collect();
        let label = if p.method == "lenth" {
            "|effect| / Lenth PSE"
        } else {
            "|standardised effect| (t)"
        };
        let mut plot = Plot::new(
            format!("Pareto chart of standardised effects ({})", t.response),
            label,
            "term",
        )
        .with(Series::line("", &x, &y).style(Style::HBars(0.6)))
        .with(
            Series::dashed(
                format!("{:.3} (alpha = {})", p.reference, p.alpha),
                &[p.reference, p.reference],
                &[-0.5, n as f64 - 0.5],
            )
            .color("#d62728"),
        );
        plot.y_categories = Some(names);
        out.push(("pareto.svg".to_string(), plot.to_svg()));
    }
    let grand = t.fitted.iter().sum::<f64>() / t.fitted.len().max(1) as f64;
    let cells: Vec<Option<Plot>> = a
        .main_effects
        .iter()
        .map(|m| {
            let x: Vec<f64> = (0..m.levels.len()).map(|i| i as f64).collect();
            let mut p = Plot::new(
                m.factor.clone(),
                m.factor.clone(),
                format!("mean of {}", t.response),
            )
            .with(Series::line("", &x, &m.means))
            .with(Series::markers("", &x, &m.means));
            p.x_categories = Some(m.levels.clone());
            p.hlines.push(grand);
            p.width = 360.0;
            p.height = 320.0;
            Some(p)
        })
        .collect();
    out.push((
        "main_effects.svg".to_string(),
        grid_svg(
            &cells,
            cells.len().min(4),
            &format!("Main effects plot for {}", t.response),
        ),
    ));
    if !a.interactions.is_empty() {
        let cells: Vec<Option<Plot>> = a
            .interactions
            .iter()
            .map(|im| {
                let x: Vec<f64> = (0..im.levels_a.len()).map(|i| i as f64).collect();
                let mut p = Plot::new(
                    format!("{} x {}", im.factor_a, im.factor_b),
                    im.factor_a.clone(),
                    format!("mean of {}", t.response),
                );
                for (j, lb) in im.levels_b.iter().enumerate() {
                    let y: Vec<f64> = im.means.iter().map(|row| row[j]).collect();
                    p.push(Series::line(format!("{} = {lb}", im.factor_b), &x, &y));
                }
                p.x_categories = Some(im.levels_a.clone());
                p.width = 420.0;
                p.height = 340.0;
                Some(p)
            })
            .collect();
        out.push((
            "interaction.svg".to_string(),
            grid_svg(
                &cells,
                cells.len().min(3),
                &format!("Interaction plot for {}", t.response),
            ),
        ));
    }
    if t.residual.df > 0 {
        let mut r = t.residuals.clone();
        r.sort_by(f64::total_cmp);
        let z = blom_scores(r.len());
        let n = r.len() as f64;
        let mean = r.iter().sum::<f64>() / n;
        let sd = (r.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0)).sqrt();
        let (lo, hi) = (r[0], r[r.len() - 1]);
        let line_x = [lo, hi];
        let line_z = [(lo - mean) / sd, (hi - mean) / sd];
        let p = Plot::new(
            format!("Normal probability plot of residuals ({})", t.response),
            "residual",
            "normal score (Blom)",
        )
        .with(Series::markers("residuals", &r, &z))
        .with(Series::line("normal fit", &line_x, &line_z));
        out.push(("normal_probability.svg".to_string(), p.to_svg()));
        let mut p = Plot::new(
            format!("Residuals versus fits ({})", t.response),
            "fitted value",
            "residual",
        )
        .with(Series::markers("", &t.fitted, &t.residuals));
        p.hlines.push(0.0);
        out.push(("residuals_vs_fits.svg".to_string(), p.to_svg()));
    }
    out
}
