//! The base model's fit: the model as a shared proxy the calibration can
//! own, its fit to the whole record and its held-out predictions.

use super::crossval::{cross_validate_by, optimum_sensitivities, Folds};
use super::fit::{fit_from_starts, Fitted};
use super::starts::base_starts;
use super::GapError;
use nalgebra::DMatrix;
use palpate_core::enrichable::{effects_of, embed, enrich};
use palpate_core::{Effect, ForwardModel, Loading};
use std::sync::Arc;

/// A shared model and the parameters held fixed in it.
type Proxy = (Arc<dyn ForwardModel>, Vec<(String, f64)>);

/// The base model as a shared (`Arc`) model the calibration can own: one of
/// its enrichments with the effect's own parameters held at "off", which
/// reproduces the base exactly. Preference goes to enrichments that need
/// nothing from the history (zero offset, tool compliance, ...).
fn base_proxy(
    base: &dyn ForwardModel,
    loading: &Loading,
    want: Option<Vec<f64>>,
) -> Result<Proxy, GapError> {
    let order = [
        Effect::ZeroOffset,
        Effect::ToolCompliance,
        Effect::Compressibility,
        Effect::MaterialForm,
        Effect::Viscoelasticity,
    ];
    let offered = effects_of(base);
    let p = base.space().len();
    let theta0 = base.space().initial();
    let want = match want {
        Some(f) => f,
        None => base.predict(&theta0, loading)?,
    };
    for effect in order.iter().chain(offered.iter()) {
        if !offered.contains(effect) {
            continue;
        }
        let Ok(rich) = enrich(base, *effect) else {
            continue;
        };
        let off = embed(rich.as_ref(), &theta0);
        if rich.space().names()[..p] != base.space().names()[..] {
            continue;
        }
        if rich.predict(&off, loading).ok().as_ref() != Some(&want) {
            continue;
        }
        let fixed = rich.space().params[p..]
            .iter()
            .zip(&off[p..])
            .map(|(s, v)| (s.name.clone(), *v))
            .collect();
        return Ok((Arc::from(rich), fixed));
    }
    Err(GapError::InvalidOption {
        option: "base",
        reason: format!(
            "{} offers no enrichment that reproduces it when switched off; nothing to diagnose",
            base.name()
        ),
    })
}

/// The base model fitted to the record.
pub(crate) struct BaseFit {
    /// The fit on all samples (parameters of the proxy).
    pub full: Fitted,
    /// The base model's own parameters at the optimum.
    pub theta: Vec<f64>,
    /// Held-out predictions (cross-validation).
    pub cv: Vec<f64>,
    /// The sensitivities of the base parameters at the optimum (first `p`
    /// columns), when the cross-validation computed them (linearised): the
    /// candidates whose "off" point reproduces the base reuse them for
    /// their score test.
    pub jac: Option<DMatrix<f64>>,
}

/// Fits the base model to all samples and cross-validates it. An expensive
/// model is fitted from the first start only, the others being fallbacks
/// when that fit fails.
pub(crate) fn fit_base(
    base: &dyn ForwardModel,
    loading: &Loading,
    observed: &[f64],
    folds: &Folds,
    linearised: bool,
) -> Result<BaseFit, GapError> {
    let p = base.space().len();
    let (starts, f0) = base_starts(base, loading, observed);
    let (model, fixed) = base_proxy(base, loading, f0)?;
    let starts: Vec<Vec<f64>> = starts.iter().map(|s| embed(model.as_ref(), s)).collect();
    let expensive = base.expensive();
    let mut fitted = fit_from_starts(
        &model,
        loading,
        observed,
        None,
        if expensive { &starts[..1] } else { &starts },
        &fixed,
        expensive,
    );
    if fitted.is_err() && expensive && starts.len() > 1 {
        fitted = fit_from_starts(&model, loading, observed, None, &starts[1..], &fixed, true);
    }
    let full = fitted?;
    let theta = full.theta[..p].to_vec();
    let mut cv_starts = vec![full.theta.clone()];
    cv_starts.extend(starts.iter().cloned());
    let jac = if linearised {
        Some(optimum_sensitivities(
            model.as_ref(),
            loading,
            &full,
            &fixed,
        )?)
    } else {
        None
    };
    let cv = cross_validate_by(
        linearised,
        &model,
        loading,
        observed,
        folds,
        &full,
        &cv_starts,
        &fixed,
        jac.as_ref(),
    )?;
    Ok(BaseFit {
        full,
        theta,
        cv,
        jac: jac.map(|(_, j)| j.columns(0, p).into_owned()),
    })
}
