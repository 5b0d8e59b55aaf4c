//! The whole analysis of a factorial experiment in one serialisable record:
//! ANOVA table, standardised effects, residual normality and equal-variance
//! checks, and the data of the effect plots.

use super::{
    anova, cells, interaction_means, main_effect_means, standardised_effects, AnovaError,
    AnovaTable, FactorColumn, InteractionMeans, MainEffectMeans, Pareto,
};
use crate::stats::{
    anderson_darling, bartlett, levene, ryan_joiner, AndersonDarling, Bartlett, Levene,
    LeveneCenter, RyanJoiner, StatsError,
};
use serde::Serialize;

/// Choices of the analysis.
#[derive(Debug, Clone, PartialEq)]
pub struct AnovaOptions {
    /// Highest interaction order in the model (`None`: all, the full model).
    pub max_order: Option<usize>,
    /// Significance level of the Pareto reference line and Lenth's margins.
    pub alpha: f64,
    /// Centre of Levene's test (Minitab uses the median: Brown-Forsythe).
    pub levene_center: LeveneCenter,
}

impl Default for AnovaOptions {
    fn default() -> Self {
        AnovaOptions {
            max_order: None,
            alpha: 0.05,
            levene_center: LeveneCenter::Median,
        }
    }
}

/// Everything `palpate anova` reports. Serialises with the table's fields
/// (`terms`, `residual`, `total`, `r2`, `adj_r2`, ...) at the top level.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Analysis {
    #[serde(flatten)]
    pub table: AnovaTable,
    /// Ryan-Joiner normality test of the residuals (`None`: undefined, see `notes`).
    pub ryan_joiner: Option<RyanJoiner>,
    /// Anderson-Darling normality test of the residuals.
    pub anderson_darling: Option<AndersonDarling>,
    /// Bartlett's test of equal variances across cells of all factors.
    pub bartlett: Option<Bartlett>,
    /// Levene's test of equal variances across cells.
    pub levene: Option<Levene>,
    pub pareto: Option<Pareto>,
    pub main_effects: Vec<MainEffectMeans>,
    pub interactions: Vec<InteractionMeans>,
    /// Why a test or chart is missing, and other caveats.
    pub notes: Vec<String>,
}

/// The value, or `None` with the reason appended to `notes`.
fn keep<T>(r: Result<T, StatsError>, notes: &mut Vec<String>) -> Option<T> {
    match r {
        Ok(v) => Some(v),
        Err(e) => {
            notes.push(e.to_string());
            None
        }
    }
}

/// Analyses `y` against `factors` (see [`anova`] and [`crate::stats`]). A
/// residual check that is undefined for these data is `None` with a note.
pub fn analyse(
    response_name: &str,
    factors: &[FactorColumn],
    y: &[f64],
    options: &AnovaOptions,
) -> Result<Analysis, AnovaError> {
    let table = anova(
        response_name,
        factors,
        y,
        options.max_order.unwrap_or(factors.len()),
    )?;
    let mut notes = Vec::new();
    if !table.balanced {
        notes.push(
            "unbalanced design: sums of squares are sequential (Type I) and depend on term order"
                .into(),
        );
    }
    for t in &table.terms {
        if t.df == 0 {
            notes.push(format!(
                "term `{}` is aliased with earlier terms and has no degree of freedom",
                t.name
            ));
        }
    }
    let (ryan, ad) = if table.residual.df == 0 {
        (None, None)
    } else {
        (
            keep(ryan_joiner(&table.residuals), &mut notes),
            keep(anderson_darling(&table.residuals), &mut notes),
        )
    };
    let groups: Vec<Vec<f64>> = cells(factors)
        .iter()
        .map(|g| g.iter().map(|&i| y[i]).collect())
        .collect();
    let bart = keep(bartlett(&groups), &mut notes);
    let lev = keep(levene(&groups, options.levene_center), &mut notes);
    if table.residual.df == 0 {
        notes.push(
            "no error degrees of freedom: F tests and residual checks are unavailable".into(),
        );
    }
    let two_level: Vec<bool> = factors.iter().map(|f| f.levels.len() == 2).collect();
    let pareto = match standardised_effects(&table, options.alpha, &two_level) {
        Ok(p) => Some(p),
        Err(e) => {
            notes.push(format!("Pareto chart: {e}"));
            None
        }
    };
    Ok(Analysis {
        main_effects: main_effect_means(factors, y),
        interactions: interaction_means(factors, y),
        table,
        ryan_joiner: ryan,
        anderson_darling: ad,
        bartlett: bart,
        levene: lev,
        pareto,
        notes,
    })
}
