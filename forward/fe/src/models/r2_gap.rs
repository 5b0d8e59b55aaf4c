//! `R2Gap`: the R2 rolling model ([`R2Rolling`]) as a base model of the
//! sim-to-real gap diagnosis (GAP.md), with the effects `inclusion`,
//! `friction` and `boundary_condition`.
//!
//! The observable is the vertical wheel force of the rolled pass
//! (`Drive::PositionMm`: the wheel pressed to RD at the first position,
//! then rolled; [`R2Rolling`]). The parameters are the tissue law's; the
//! nodules the model knows of (`rolling.nodules`) have the tissue's law with
//! its moduli multiplied by `contrast`, so the model stays homogeneous of
//! degree one in the tissue's moduli (the contact penalties scale with the
//! tissue's shear modulus, Coulomb friction with the normal traction): the
//! diagnosis's cache serves a whole ray of moduli from one solve.
//!
//! Effects (each "off" at a reachable parameter value):
//!
//! * `inclusion` (offered when the base has no nodule): one circular nodule
//!   (the model's `nodule_radius`) with parameters `inclusion_contrast`
//!   (ratio of its moduli to the tissue's, in [1, 100], off = 1),
//!   `inclusion_x_mm` (centre along the block, within the rolled path) and
//!   `inclusion_depth_mm` (centre below the top, from the radius + 1.5 mm to
//!   the height - radius - 1.5 mm). At contrast 1 the nodule is tissue, so
//!   the enriched prediction equals the base one to within the
//!   discretisation difference of the two meshes (the nodule's O-grid), not
//!   bit for bit: a bit-for-bit "off" path would put that mesh difference
//!   into the one-sided finite difference at contrast 1 and break the score
//!   test. x and depth are identified only when the contrast is above 1
//!   (Davies' problem): the refit starts with the nodule under the middle of
//!   the path at the middle depth, the score step in the contrast alone.
//!   Moving the nodule changes the mesh (column counts of the strips
//!   between the nodule box and the block ends), so the prediction is
//!   piecewise smooth in x and depth with jumps of the size of the
//!   discretisation error.
//! * `friction` (offered when the model's friction is fixed): the Coulomb
//!   coefficient of the wheel, `friction` in [0, 2], plausible [0, 0.8], off
//!   = the model's fixed value. A frictional contact depends on the path,
//!   so the prediction is always the rolled pass (never presses at the
//!   positions).
//! * `boundary_condition` (offered when the base is bonded): the bottom
//!   sliding instead of bonded ([`Support::Sliding`]), a discrete
//!   switch with no parameter.

use palpate_core::{
    Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable, ParamRole,
    ParamSpace, ParamSpec,
};

use crate::model::{friction_param, law_space, Support};
use crate::r2::{Nodule, R2Rolling};

/// Clearance (mm) between an added nodule and the top or bottom face,
/// beyond its radius: the mesh generator's minimum (1 mm) plus a margin for
/// its matrix ring.
const INCLUSION_CLEARANCE: f64 = 1.5;

/// R2 for the gap diagnosis: the rolled pass's vertical force, tissue
/// parameters, optional effects.
#[derive(Debug, Clone, PartialEq)]
pub struct R2Gap {
    /// The rolling model (geometry, mesh, fixed friction, support). Its
    /// `nodule_law` is replaced by its `law`.
    pub rolling: R2Rolling,
    /// Modulus ratio nodule / tissue of `rolling.nodules`.
    pub contrast: f64,
    /// Friction is the parameter `friction` (the `friction` effect).
    friction_is_parameter: bool,
    /// One added nodule with contrast, x and depth as parameters (the
    /// `inclusion` effect).
    inclusion: bool,
    space: ParamSpace,
}

impl R2Gap {
    /// The base model: `rolling` with its nodules' moduli `contrast` times
    /// the tissue's (contrast is unused without nodules).
    pub fn new(rolling: R2Rolling, contrast: f64) -> Self {
        let mut rolling = rolling;
        let law = *rolling.law();
        rolling.set_nodule_law(law);
        R2Gap {
            space: law_space(&law),
            rolling,
            contrast,
            friction_is_parameter: false,
            inclusion: false,
        }
    }

    /// Number of tissue parameters.
    fn p_law(&self) -> usize {
        self.rolling.law().params().len()
    }

    /// Bounds of an added nodule's depth (mm).
    fn depth_range(&self) -> (f64, f64) {
        let r = self.rolling.nodule_radius + INCLUSION_CLEARANCE;
        (r, self.rolling.height - r)
    }

    /// The rolling model and its full parameter vector (tissue, nodule) for
    /// `theta`.
    pub fn resolve(&self, theta: &[f64]) -> Result<(R2Rolling, Vec<f64>), ForwardError> {
        self.space.check(theta)?;
        let p = self.p_law();
        let mut m = self.rolling.clone();
        let mut k = p;
        if self.friction_is_parameter {
            m.friction = theta[k];
            k += 1;
        }
        let mut contrast = self.contrast;
        if self.inclusion {
            contrast = theta[k];
            m.nodules.push(Nodule {
                x: theta[k + 1],
                depth: theta[k + 2],
            });
        }
        let specs = law_space(m.law());
        let nodule: Vec<f64> = theta[..p]
            .iter()
            .zip(&specs.params)
            .map(|(&v, s)| {
                if s.role == ParamRole::Modulus {
                    v * contrast
                } else {
                    v
                }
            })
            .collect();
        let mut full = theta[..p].to_vec();
        full.extend(nodule);
        Ok((m, full))
    }
}

struct R2GapEval<'a> {
    model: &'a R2Gap,
}

impl Evaluator for R2GapEval<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let (m, full) = self.model.resolve(theta)?;
        let mut ev = m.evaluator();
        ev.predict_into(&full, loading, out)
    }
}

impl ForwardModel for R2Gap {
    fn name(&self) -> String {
        let mut name = self.rolling.name();
        if !self.rolling.nodules.is_empty() {
            name += &format!(", nodule contrast {}", self.contrast);
        }
        if self.friction_is_parameter {
            name += ", friction free";
        }
        if self.inclusion {
            name += ", + one nodule (contrast, x, depth free)";
        }
        name
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        Observable::ForceN
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(R2GapEval { model: self })
    }
    /// A nonlinear FE rolled pass per prediction.
    fn expensive(&self) -> bool {
        true
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        Some(self)
    }
}

impl Enrichable for R2Gap {
    /// One enrichment at a time: an enriched model offers none.
    fn effects(&self) -> Vec<Effect> {
        if self.friction_is_parameter || self.inclusion || self.rolling.base != Support::Bonded {
            return Vec::new();
        }
        let mut v = Vec::new();
        if self.rolling.nodules.is_empty() {
            v.push(Effect::Inclusion);
        }
        v.push(Effect::Friction);
        v.push(Effect::BoundaryCondition);
        v
    }
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        Ok(Box::new(self.enriched(effect)?))
    }
}

impl R2Gap {
    /// The model with `effect` added ([`Enrichable::enrich`], unboxed).
    pub fn enriched(&self, effect: Effect) -> Result<R2Gap, ForwardError> {
        if !self.effects().contains(&effect) {
            return Err(palpate_core::enrichable::not_applicable(
                effect,
                &self.name(),
            ));
        }
        let mut m = self.clone();
        match effect {
            Effect::Inclusion => {
                let (d_lo, d_hi) = self.depth_range();
                let (x_lo, x_hi) = (self.rolling.press_x, self.rolling.roll_to);
                m.inclusion = true;
                m.space = self.space.extended(&[
                    ParamSpec::new("inclusion_contrast", "1", 1.0, 100.0, 1.0),
                    ParamSpec::new("inclusion_x_mm", "mm", x_lo, x_hi, 0.5 * (x_lo + x_hi)),
                    ParamSpec::new("inclusion_depth_mm", "mm", d_lo, d_hi, 0.5 * (d_lo + d_hi)),
                ]);
            }
            Effect::Friction => {
                m.friction_is_parameter = true;
                m.space = self
                    .space
                    .extended(&[friction_param(self.rolling.friction)]);
            }
            _ => m.rolling.base = Support::Sliding,
        }
        Ok(m)
    }
}
