//! A prediction cache for expensive models, shared by the base model and
//! every enrichment of one diagnosis, that also exploits an exact scale
//! invariance of the model when it has one.
//!
//! The diagnosis predicts the same model at the same parameters many times
//! (a fit's start and its final statistics, the "off" point of every
//! candidate, the base fit inside a candidate's screen, the linearised
//! cross-validation's centre), and for a finite-element model each
//! prediction is a nonlinear solve of seconds. [`Memo`] keys predictions by
//! the model's name (which states its configuration: law, friction, base,
//! wrapper), the parameter bits and the loading; a cache lives for one
//! diagnosis, so models that differ only in what the name omits (the mesh)
//! never meet in it.
//!
//! **Homogeneity in the moduli.** A hyperelastic body under prescribed
//! displacement whose contact penalties scale with the shear modulus (as the
//! FE needle and punch models do) responds to all its moduli scaled by a
//! with the same deformation and a times the force:
//! f(a m, s) = a f(m, s) for every non-modulus parameter s (friction, a
//! zero offset, Prony weights and time constants, a sliding base). The
//! force is then known along each ray through the origin from one solve:
//! the least-squares modulus of a fit, the finite-difference column of a
//! single modulus (exactly f / m, Euler's theorem), the base fit itself
//! (variable projection, Golub & Pereyra 1973: the linear modulus
//! eliminated analytically, only the non-modulus parameters need solves).
//! Whether a model has the property is not assumed: it is *measured* the
//! first time two parameter vectors on one ray are both solved (the base
//! fit's start scaled by its least-squares factor, a candidate's screened
//! start), and the shortcut is used for that model only when the two
//! predictions agree to [`HOMOGENEITY_TOL`] of the force scale. A model
//! where they do not (a compressible law with its bulk modulus fixed as a
//! compliance, an enrichment whose parameter is a stiffness) is solved
//! every time.

use palpate_core::{
    Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable, Output,
    ParamRole, ParamSpace,
};
use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::sync::{Arc, Mutex};

/// Largest difference between a solve and the scaled solve on the same ray,
/// relative to the largest |force| of the record, accepted as homogeneity.
/// Far above the nonlinear solver's tolerance (the residual norm is reduced
/// to ~1e-8 of the load; measured differences on N1 are ~1e-10), far below
/// any noise level the diagnosis resolves (~1e-3 of the peak force).
pub const HOMOGENEITY_TOL: f64 = 1e-6;

/// What is known of one model (by name) in the cache.
#[derive(Default)]
struct ModelEntry {
    /// Predictions by parameter bits (rounded, [`key_of`]).
    exact: HashMap<Vec<u64>, Vec<f64>>,
    /// Predictions divided by the first modulus, by the parameter bits with
    /// the moduli divided by the first one (the ray).
    ray: HashMap<Vec<u64>, Vec<f64>>,
    /// `Some(true)` once a second solve on a ray agreed with the scaled
    /// first one; `Some(false)` once one did not.
    homogeneous: Option<bool>,
}

/// The shared cache of one diagnosis.
#[derive(Default)]
pub(crate) struct Cache {
    models: Mutex<HashMap<(String, u64), ModelEntry>>,
}

/// The bits of `v` rounded to ~1e-12 relative (the last 12 of the 52
/// mantissa bits): parameter vectors that differ only by the rounding of an
/// unbounded-transform round trip (0.2 and 0.20000000000000004) share a
/// key. A relative change of 1e-12 is far below the finite-difference steps
/// (>= 1e-5) and the solver's tolerance, so the cached prediction stands for
/// both.
fn rounded_bits(v: f64) -> u64 {
    if v == 0.0 || !v.is_finite() {
        return v.to_bits() & !(1 << 63);
    }
    (v.to_bits() + 0x800) & !0xFFF
}

/// The key of a parameter vector.
fn key_of(theta: &[f64]) -> Vec<u64> {
    theta.iter().map(|&v| rounded_bits(v)).collect()
}

/// A fingerprint of a loading history.
fn loading_key(loading: &Loading) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    loading.drive_kind.column().hash(&mut h);
    for v in &loading.drive {
        v.to_bits().hash(&mut h);
    }
    if let Some(t) = &loading.time {
        for v in t {
            v.to_bits().hash(&mut h);
        }
    }
    loading.drive.len().hash(&mut h);
    h.finish()
}

/// The ray of `theta`: the moduli divided by the first one (which becomes
/// exactly 1), with that modulus; `None` without a positive finite modulus.
fn ray_of(space: &ParamSpace, theta: &[f64]) -> Option<(Vec<u64>, f64)> {
    let first = space
        .params
        .iter()
        .position(|s| s.role == ParamRole::Modulus)?;
    let m = theta[first];
    if !(m.is_finite() && m > 0.0) {
        return None;
    }
    let key = space
        .params
        .iter()
        .zip(theta)
        .map(|(s, &v)| {
            // (a c2) / (a c1) and c2 / c1 fall on the same rounded key
            rounded_bits(if s.role == ParamRole::Modulus {
                v / m
            } else {
                v
            })
        })
        .collect();
    Some((key, m))
}

/// The model behind a [`Memo`]: the caller's base model (borrowed) or an
/// enrichment (owned).
enum Inner<'a> {
    Borrowed(&'a dyn ForwardModel),
    Shared(Arc<dyn ForwardModel>),
}

/// A model whose predictions go through a [`Cache`]; its enrichments do too.
pub(crate) struct Memo<'a> {
    inner: Inner<'a>,
    cache: Arc<Cache>,
}

impl<'a> Memo<'a> {
    /// The caller's model, with a new cache.
    pub fn borrowed(inner: &'a dyn ForwardModel) -> Self {
        Memo {
            inner: Inner::Borrowed(inner),
            cache: Arc::new(Cache::default()),
        }
    }

    fn model(&self) -> &dyn ForwardModel {
        match &self.inner {
            Inner::Borrowed(m) => *m,
            Inner::Shared(m) => m.as_ref(),
        }
    }

    /// The cached prediction at `theta`, if any (exact, or on a ray of a
    /// model found homogeneous).
    fn lookup(&self, key: &(String, u64), theta: &[f64]) -> Option<Vec<f64>> {
        let models = self.cache.models.lock().ok()?;
        let entry = models.get(key)?;
        if let Some(f) = entry.exact.get(&key_of(theta)) {
            return Some(f.clone());
        }
        if entry.homogeneous == Some(true) {
            let (ray, m) = ray_of(self.model().space(), theta)?;
            return entry
                .ray
                .get(&ray)
                .map(|unit| unit.iter().map(|v| v * m).collect());
        }
        None
    }

    /// Stores a solve, and tests homogeneity against a solve on its ray.
    fn store(&self, key: (String, u64), theta: &[f64], f: &[f64]) {
        let Ok(mut models) = self.cache.models.lock() else {
            return;
        };
        let entry = models.entry(key).or_default();
        entry.exact.insert(key_of(theta), f.to_vec());
        let Some((ray, m)) = ray_of(self.model().space(), theta) else {
            return;
        };
        let unit: Vec<f64> = f.iter().map(|v| v / m).collect();
        match entry.ray.get(&ray) {
            Some(other) if entry.homogeneous.is_none() => {
                let scale = unit.iter().chain(other).fold(0.0f64, |a, v| a.max(v.abs()));
                let agree = scale > 0.0
                    && unit
                        .iter()
                        .zip(other)
                        .all(|(a, b)| (a - b).abs() <= HOMOGENEITY_TOL * scale);
                entry.homogeneous = Some(agree);
            }
            Some(_) => {}
            None => {
                entry.ray.insert(ray, unit);
            }
        }
    }
}

struct MemoEval<'m, 'a> {
    model: &'m Memo<'a>,
    inner: Box<dyn Evaluator + 'm>,
}

impl Evaluator for MemoEval<'_, '_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let key = (self.model.model().name(), loading_key(loading));
        if let Some(f) = self.model.lookup(&key, theta) {
            if f.len() == out.len() {
                out.copy_from_slice(&f);
                return Ok(());
            }
        }
        self.inner.predict_into(theta, loading, out)?;
        self.model.store(key, theta, out);
        Ok(())
    }
}

impl ForwardModel for Memo<'_> {
    fn name(&self) -> String {
        self.model().name()
    }
    fn space(&self) -> &ParamSpace {
        self.model().space()
    }
    fn observable(&self) -> Observable {
        self.model().observable()
    }
    /// The first output only: the diagnosis fits that one.
    fn outputs(&self) -> Vec<Output> {
        self.model().outputs().into_iter().take(1).collect()
    }
    fn expensive(&self) -> bool {
        self.model().expensive()
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(MemoEval {
            model: self,
            inner: self.model().evaluator(),
        })
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        self.model()
            .as_enrichable()
            .map(|_| self as &dyn Enrichable)
    }
}

impl Enrichable for Memo<'_> {
    fn effects(&self) -> Vec<Effect> {
        palpate_core::enrichable::effects_of(self.model())
    }
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        let rich = palpate_core::enrichable::enrich(self.model(), effect)?;
        Ok(Box::new(Memo {
            inner: Inner::Shared(Arc::from(rich)),
            cache: self.cache.clone(),
        }))
    }
    fn embed(&self, base_theta: &[f64]) -> Vec<f64> {
        palpate_core::enrichable::embed(self.model(), base_theta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use palpate_core::{Drive, ParamSpec};
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// F = (k1 + k2) (d - d0) with k1, k2 moduli; `bent` adds a term that
    /// is not homogeneous in them.
    struct Spring {
        space: ParamSpace,
        bent: bool,
        calls: Arc<AtomicUsize>,
    }

    struct Eval<'a>(&'a Spring);

    impl Evaluator for Eval<'_> {
        fn predict_into(
            &mut self,
            t: &[f64],
            l: &Loading,
            out: &mut [f64],
        ) -> Result<(), ForwardError> {
            self.0.calls.fetch_add(1, Ordering::Relaxed);
            for (o, d) in out.iter_mut().zip(&l.drive) {
                *o = (t[0] + t[1]) * (d - t[2]);
                if self.0.bent {
                    *o += 0.1 * d * d;
                }
            }
            Ok(())
        }
    }

    impl ForwardModel for Spring {
        fn name(&self) -> String {
            format!("spring bent {}", self.bent)
        }
        fn space(&self) -> &ParamSpace {
            &self.space
        }
        fn observable(&self) -> Observable {
            Observable::ForceN
        }
        fn evaluator(&self) -> Box<dyn Evaluator + '_> {
            Box::new(Eval(self))
        }
    }

    fn spring(bent: bool) -> (Memo<'static>, Arc<AtomicUsize>) {
        let calls = Arc::new(AtomicUsize::new(0));
        let space = ParamSpace::new(vec![
            ParamSpec::new("k1", "MPa", 0.0, 10.0, 1.0).with_role(ParamRole::Modulus),
            ParamSpec::new("k2", "MPa", 0.0, 10.0, 1.0).with_role(ParamRole::Modulus),
            ParamSpec::new("d0", "mm", -1.0, 1.0, 0.0).with_role(ParamRole::Offset),
        ]);
        let model = Spring {
            space,
            bent,
            calls: calls.clone(),
        };
        let model: &'static Spring = Box::leak(Box::new(model));
        (Memo::borrowed(model), calls)
    }

    #[test]
    fn repeats_and_rays_of_a_homogeneous_model_are_not_solved_again() {
        let (m, calls) = spring(false);
        let l = Loading::quasi_static(Drive::DisplacementMm, vec![0.0, 0.5, 1.0, 2.0]);
        let a = m.predict(&[1.0, 2.0, 0.1], &l).unwrap();
        assert_eq!(m.predict(&[1.0, 2.0, 0.1], &l).unwrap(), a);
        assert_eq!(calls.load(Ordering::Relaxed), 1);
        // a second point on the ray is solved once (the homogeneity test) ...
        let b = m.predict(&[2.0, 4.0, 0.1], &l).unwrap();
        assert_eq!(calls.load(Ordering::Relaxed), 2);
        // ... then every point of the ray is served by scaling
        let c = m.predict(&[0.3, 0.6, 0.1], &l).unwrap();
        assert_eq!(calls.load(Ordering::Relaxed), 2);
        for ((x, y), z) in a.iter().zip(&b).zip(&c) {
            assert!((2.0 * x - y).abs() < 1e-12 && (0.3 * x - z).abs() < 1e-12);
        }
        // another offset is another ray; another loading another key
        m.predict(&[1.0, 2.0, 0.2], &l).unwrap();
        m.predict(
            &[1.0, 2.0, 0.1],
            &Loading::quasi_static(Drive::DisplacementMm, vec![0.0, 1.0]),
        )
        .unwrap();
        assert_eq!(calls.load(Ordering::Relaxed), 4);
    }

    #[test]
    fn a_model_that_is_not_homogeneous_is_solved_every_time() {
        let (m, calls) = spring(true);
        let l = Loading::quasi_static(Drive::DisplacementMm, vec![0.0, 0.5, 1.0, 2.0]);
        m.predict(&[1.0, 2.0, 0.1], &l).unwrap();
        m.predict(&[2.0, 4.0, 0.1], &l).unwrap();
        let c = m.predict(&[0.3, 0.6, 0.1], &l).unwrap();
        assert_eq!(calls.load(Ordering::Relaxed), 3);
        assert!((c[3] - (0.9 * 1.9 + 0.4)).abs() < 1e-12);
    }
}
