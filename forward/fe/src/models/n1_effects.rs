//! The effects of the gap diagnosis that the axisymmetric cylinder
//! ([`N1Setup`], N1 and every described cylinder) offers, and the models
//! enriched with them ([`crate::model::Setup::effects`],
//! [`crate::model::Setup::enrich`]):
//!
//! * `friction` — the friction coefficient becomes a parameter (bounds 0..2).
//! * `boundary_condition` — a support other than described, in two forms
//!   (`Enrichable::enrich_forms`; the diagnosis keeps the one that predicts
//!   held-out samples best): `thickness`, the default where the body has
//!   room for it, the specimen's thickness as the last parameter
//!   (`thickness_mm`; a gel layer taken for a block), and `sliding_base`,
//!   the base sliding radially (`u_z = 0` only) instead of bonded. The
//!   latter is a discrete switch: the enriched model has the same parameters
//!   as the base model, and a gap diagnosis compares the two fits. (A
//!   continuous bonded-to-sliding blend would need a base spring whose
//!   stiffness spans many decades, badly conditioned near "bonded"; the
//!   switch answers the same question.) What is offered depends on the
//!   body only, not on whether it was built as N1 or from a description.
//! * `material_form` — the next richer law (neo-Hookean -> reduced
//!   polynomial N=2 with a stiffening C20 >= 0, ...; `palpate_enrich::richer_law`).
//! * `zero_offset` — contact starts at a recorded displacement d0
//!   (`palpate_enrich::ZeroOffset`, the same wrapper as for C1).
//! * `modelling_space` — on N1's 70 x 80 mm specimen only: the same needle
//!   in 3D ([`N1Setup::in_3d`]).

use palpate_core::enrichable::{not_applicable, one_form, EffectForm};
use palpate_core::{Effect, ForwardError, ForwardModel, ParamSpec};
use palpate_enrich::{richer_law, MaterialForm, ZeroOffset};
use std::sync::Arc;

use crate::model::{friction_param, FeModel, Setup, Support};
use crate::n1::N1Setup;
use crate::tool::ToolShape;
use crate::FeError;

impl N1Setup {
    /// With the thickness a parameter: the specimen at that thickness,
    /// meshed by the lines of its own height moved with the base.
    pub(super) fn at_thickness(&self, extra: &[f64]) -> Result<N1Setup, FeError> {
        let mut g = self.clone();
        if self.thickness_is_parameter {
            let n = self.extra_len();
            let h = *extra.get(n - 1).ok_or_else(|| FeError::InvalidConfig {
                field: "parameters".into(),
                reason: format!("{} parameters after the law's, {n} expected", extra.len()),
            })?;
            if !(h > 0.0 && h.is_finite()) {
                return Err(FeError::InvalidConfig {
                    field: "thickness_mm".into(),
                    reason: format!("{h} mm: expected a finite thickness > 0"),
                });
            }
            g.mesh_height = Some(self.mesh_height.unwrap_or(self.height));
            g.height = h;
        }
        Ok(g)
    }
    /// The effects offered ([`Setup::effects`]).
    pub(super) fn offered_effects(&self) -> Vec<Effect> {
        let mut v = Vec::new();
        if self.friction_offered() {
            v.push(Effect::Friction);
        }
        if self.boundary_offered() {
            v.push(Effect::BoundaryCondition);
        }
        // (one enrichment at a time: the richer law of a model whose friction
        // is already a parameter is not offered)
        if self.material_form_offered() {
            v.push(Effect::MaterialForm);
        }
        v.push(Effect::ZeroOffset);
        if self.modelling_space_applies() {
            v.push(Effect::ModellingSpace);
        }
        v
    }
    /// The model with `effect` ([`Setup::enrich`]).
    pub(super) fn enriched(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        match effect {
            Effect::Friction if self.friction_offered() => {
                let mut m = self.clone();
                m.friction_is_parameter = true;
                if let Some(space) = &mut m.space {
                    // the tool's friction comes before the base's
                    let at = space.params.len() - usize::from(m.base_friction_is_parameter);
                    space.params.insert(at, friction_param(m.friction));
                }
                Ok(Box::new(FeModel::from_setup(m)))
            }
            Effect::BoundaryCondition if self.boundary_offered() => {
                let first = self.boundary_forms().remove(0);
                Ok(Box::new(FeModel::from_setup(first.1)))
            }
            Effect::MaterialForm if self.material_form_offered() => {
                let richer = richer_law(&self.law).expect("checked above");
                let mut inner = self.clone();
                inner.law = richer.law;
                inner.space = None;
                let space = richer.space.clone();
                inner.law_bounds = Some(space.clone());
                Ok(Box::new(MaterialForm::new(
                    Box::new(FeModel::from_setup(inner)),
                    richer.embed_law_params.clone(),
                    self.law.to_string(),
                    space,
                )))
            }
            Effect::ZeroOffset => Ok(Box::new(ZeroOffset::from_arc(Arc::new(
                FeModel::from_setup(self.clone()),
            )))),
            Effect::ModellingSpace if self.modelling_space_applies() => Ok(Box::new(self.in_3d())),
            _ => Err(not_applicable(effect, &self.name())),
        }
    }
}

impl N1Setup {
    /// The forms of `effect` ([`Setup::enrich_forms`]): `boundary_condition`
    /// has two ([`N1Setup::boundary_forms`]), the others one.
    pub(super) fn enriched_forms(&self, effect: Effect) -> Result<Vec<EffectForm>, ForwardError> {
        if effect == Effect::BoundaryCondition && self.boundary_offered() {
            return Ok(self
                .boundary_forms()
                .into_iter()
                .map(|(name, m)| EffectForm {
                    name: name.into(),
                    model: Box::new(FeModel::from_setup(m)),
                })
                .collect());
        }
        Ok(one_form(self.enriched(effect)?))
    }

    /// Whether `boundary_condition` is offered: the base is bonded (not on
    /// a rigid plane) and the thickness is not already a parameter. The
    /// rule is the body's, not the route's: N1 built by
    /// [`crate::N1Needle::new`] and its preset built from a description
    /// offer the same.
    fn boundary_offered(&self) -> bool {
        self.base == Support::Bonded && self.base_friction.is_none() && !self.thickness_is_parameter
    }

    /// The forms of `boundary_condition` of a bonded finite body, the
    /// default first: `thickness` (the specimen's thickness a parameter,
    /// where [`N1Setup::thickness_offered`]: a specimen thinner or thicker
    /// than described, as a gel layer taken for a block) and
    /// `sliding_base` (the base slides radially, `u_z = 0` only: a
    /// discrete switch with the base's parameters).
    fn boundary_forms(&self) -> Vec<(&'static str, N1Setup)> {
        let mut forms = Vec::new();
        if self.thickness_offered() {
            let mut m = self.clone();
            m.thickness_is_parameter = true;
            let p = self.thickness_param();
            if let Some(space) = &mut m.space {
                space.params.push(p);
            }
            forms.push(("thickness", m));
        }
        let mut m = self.clone();
        m.base = Support::Sliding;
        forms.push(("sliding_base", m));
        forms
    }
}

impl N1Setup {
    /// Whether the parameters after the law's are none (the model is the
    /// law's alone, as the richer law's wrapper needs).
    fn law_only(&self) -> bool {
        self.prony_parameters == 0
            && self.materials.is_empty()
            && !self.friction_is_parameter
            && !self.base_friction_is_parameter
            && !self.thickness_is_parameter
    }

    /// Whether `friction` is offered: the tool's coefficient is a finite
    /// number (and the thickness, which must stay the last parameter, is
    /// not one).
    fn friction_offered(&self) -> bool {
        !self.friction_is_parameter && self.friction.is_finite() && !self.thickness_is_parameter
    }

    /// Whether `boundary_condition` takes the form of the specimen's
    /// thickness: a cylinder (whose height a lab may have given wrong, or
    /// as "a large block") of one material on a bonded base, pressed by a
    /// tool (not platens, whose travel is the height's), with room below
    /// the fine zone to move its base. N1's 80 mm cylinder is one.
    fn thickness_offered(&self) -> bool {
        self.base == Support::Bonded
            && self.base_friction.is_none()
            && self.layers.is_empty()
            && !self.mirror
            && self.tool != ToolShape::Platen
            && !self.thickness_is_parameter
            && self.thickness_range().is_some()
    }

    /// The range of the thickness parameter (mm): from one and a half
    /// fine zones (and a tenth of the height) to twice the height; `None`
    /// when the fine zone leaves no room.
    fn thickness_range(&self) -> Option<(f64, f64)> {
        let h = self.mesh_height.unwrap_or(self.height);
        let lower = (1.5 * self.kept_depth()).max(0.1 * h);
        (lower < 0.9 * h).then_some((lower, 2.0 * h))
    }

    /// The `thickness_mm` parameter, starting at the height (the effect
    /// off: the base model, bit for bit).
    pub(super) fn thickness_param(&self) -> ParamSpec {
        let h = self.mesh_height.unwrap_or(self.height);
        let (lower, upper) = self.thickness_range().unwrap_or((h, h));
        ParamSpec::new("thickness_mm", "mm", lower, upper, h)
    }

    /// Whether `material_form` is offered: one material, its law's
    /// parameters the only ones, and a richer law exists.
    fn material_form_offered(&self) -> bool {
        self.law_only() && richer_law(&self.law).is_some()
    }
}

impl N1Setup {
    /// Whether `modelling_space` is offered: the axisymmetric model of N1's
    /// 70 x 80 mm cylinder with a bonded base, its friction fixed, elastic
    /// (N3 is that specimen's block, with neither a sliding base nor
    /// viscoelasticity).
    fn modelling_space_applies(&self) -> bool {
        // the 3D model is N3's block, the 3D counterpart of N1's specimen only
        self.radius == 35.0
            && self.height == 80.0
            && !self.mirror
            && self.base == Support::Bonded
            && self.base_friction.is_none()
            && self.law_only()
            && self.layers.is_empty()
            && self.friction.is_finite()
            && self.tool != ToolShape::Platen
            && self.prony.is_none()
    }

    /// The `modelling_space` enrichment: the same needle, law, bulk
    /// treatment and friction in 3D ([`crate::N3Needle`], docs/benchmarks.md N3:
    /// the quarter of a 70 x 80 x 80 mm block, 8-node mixed hexahedra, mesh
    /// level 1, 25-41 s of CPU to 10 mm against N1's ~1.5 s on the coarse
    /// mesh). A discrete switch like `boundary_condition`: the same
    /// parameters, compared by their two fits. The cylinder of N1 (radius
    /// 35 mm) becomes N3's square block (half-widths 35 and 40 mm), part of
    /// what "3D instead of axisymmetric" means for this specimen.
    pub fn in_3d(&self) -> crate::N3Needle {
        let mut m = crate::N3Needle::new(self.law);
        m.bulk = self.bulk;
        m.friction = self.friction;
        m.tool = self.tool;
        m.penalty = self.penalty;
        m.penetration_tol = self.penetration_tol;
        m
    }
}

#[cfg(test)]
mod tests {
    use crate::experiment::{Experiment, ExperimentModel};
    use crate::{MeshDensity, N1Needle};
    use palpate_core::enrichable::{effects_of, embed, enrich_forms};
    use palpate_core::{Drive, Effect, ForwardModel, Loading};
    use palpate_material::Law;

    /// The N1 preset at mesh level 1 (N1's coarse mesh), built from its
    /// description.
    fn preset_coarse() -> Box<dyn ForwardModel> {
        let text = Experiment::preset_toml("N1")
            .unwrap()
            .replace("level = 2", "level = 1");
        let e = Experiment::from_toml_str(&text, "n1.toml").unwrap();
        match e.model().unwrap() {
            ExperimentModel::Cylinder(m) => {
                let mut n1 = N1Needle::new(Law::NeoHookean);
                n1.mesh = MeshDensity::COARSE;
                assert_eq!(m.build_mesh().unwrap(), n1.build_mesh().unwrap());
                Box::new(m)
            }
            other => panic!("{}", other.kind()),
        }
    }

    /// `--benchmark N1` and `--experiment N1` are one body: the same
    /// effects, each in the same forms with the same parameters, and on
    /// the same mesh the same forces, base and enriched, at the effect's
    /// "off" point and away from it.
    #[test]
    fn the_n1_preset_offers_what_the_n1_model_offers() {
        let mut n1 = N1Needle::new(Law::NeoHookean);
        n1.mesh = MeshDensity::COARSE;
        let preset = preset_coarse();
        let offered = effects_of(&n1);
        assert_eq!(effects_of(preset.as_ref()), offered);
        assert!(offered.contains(&Effect::BoundaryCondition), "{offered:?}");
        for &e in &offered {
            let (a, b) = (
                enrich_forms(&n1, e).unwrap(),
                enrich_forms(preset.as_ref(), e).unwrap(),
            );
            assert_eq!(a.len(), b.len(), "{e:?}");
            for (fa, fb) in a.iter().zip(&b) {
                // the same parameters and bounds (the preset's C10 starts
                // at its material's value)
                let bounds = |m: &dyn ForwardModel| -> Vec<(String, f64, f64)> {
                    let s = m.space();
                    s.params
                        .iter()
                        .map(|p| (p.name.clone(), p.lower, p.upper))
                        .collect()
                };
                assert_eq!(
                    bounds(fa.model.as_ref()),
                    bounds(fb.model.as_ref()),
                    "{e:?}"
                );
                assert_eq!(
                    effects_of(fa.model.as_ref()),
                    effects_of(fb.model.as_ref()),
                    "{e:?}"
                );
            }
        }
        let forms = enrich_forms(&n1, Effect::BoundaryCondition).unwrap();
        let names: Vec<&str> = forms.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(names, ["thickness", "sliding_base"]);
        assert_eq!(forms[0].model.space().names(), ["C10", "thickness_mm"]);
        assert_eq!(forms[1].model.space().names(), ["C10"]);

        let loading = Loading::quasi_static(Drive::DisplacementMm, vec![0.5, 1.0]);
        let c10 = 1.1e-3;
        let close = |a: &[f64], b: &[f64]| {
            assert_eq!(a.len(), b.len());
            for (x, y) in a.iter().zip(b) {
                assert!((x - y).abs() <= 1e-9 * y.abs(), "{a:?} vs {b:?}");
            }
        };
        let f = n1.predict(&[c10], &loading).unwrap();
        close(&preset.predict(&[c10], &loading).unwrap(), &f);
        let preset_forms = enrich_forms(preset.as_ref(), Effect::BoundaryCondition).unwrap();
        for (fa, fb) in forms.iter().zip(&preset_forms) {
            let off = embed(fa.model.as_ref(), &[c10]);
            assert_eq!(off, embed(fb.model.as_ref(), &[c10]));
            let at_off = fa.model.predict(&off, &loading).unwrap();
            close(&fb.model.predict(&off, &loading).unwrap(), &at_off);
            if fa.name == "thickness" {
                // the effect off is the base, bit for bit
                assert_eq!(at_off, f);
                let thin = [c10, 40.0];
                let f_thin = fa.model.predict(&thin, &loading).unwrap();
                close(&fb.model.predict(&thin, &loading).unwrap(), &f_thin);
                assert!(f_thin[1] > f[1], "40 mm {f_thin:?} 80 mm {f:?}");
            } else {
                assert!(at_off[1] < f[1], "sliding {at_off:?} bonded {f:?}");
            }
        }
    }
}
