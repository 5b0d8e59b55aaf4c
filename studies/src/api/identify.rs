//! The staged identification of a Q1 ramp-and-hold record by finite
//! elements (`palpate calibrate --benchmark Q1`; the recipe is
//! [`crate::apps::two_stage`]): its options by name, the record from a
//! file or from arrays, the run with its lines to an [`Observer`].

use std::path::Path;

use palpate_material::Law;

use super::Observer;
use crate::apps::two_stage::{identify, Q1Record, TwoStageOptions, TwoStageResult};
use crate::records::arrays::{record_for, ArrayRecord};
use crate::records::{ReadOptions, TestData, TestKind};

/// The options of the staged identification; `None` is the default of
/// [`TwoStageOptions::new`] (`palpate calibrate --help` gives each).
#[derive(Debug, Clone, Default)]
pub struct Q1Options {
    /// The stages in order, e.g. `elastic,relaxation`.
    pub stages: Option<String>,
    /// Prony terms.
    pub prony_terms: Option<usize>,
    /// Element size under the punch of the fits' mesh (mm).
    pub fit_mesh: Option<f64>,
    /// Correct each fit to a finer mesh with this element size (mm).
    pub correct_mesh: Option<f64>,
    /// Time step of the viscoelastic runs (s).
    pub time_step: Option<f64>,
    /// Radius of the punch's rounded edge (mm).
    pub edge_radius: Option<f64>,
    /// Radius of the edge of the fit mesh's punch with `correct_mesh` (mm).
    pub fit_edge_radius: Option<f64>,
    /// Check the polish on a mesh with this element size (mm).
    pub mesh_check: Option<f64>,
    /// Also fit every parameter at once from the default start.
    pub compare: bool,
    /// Profile-likelihood intervals of the polished parameters.
    pub profile: bool,
}

impl Q1Options {
    /// [`Q1Options::two_stage`] for the law named `law` (the error names `--law`).
    pub fn for_law(&self, law: &str) -> anyhow::Result<TwoStageOptions> {
        let parsed: Law = law
            .parse()
            .map_err(|e| anyhow::anyhow!("--law {law}: {e}"))?;
        self.two_stage(parsed)
    }

    /// The identification's options for `law`; the errors name the
    /// command line's options (`--stages`, `--fit-mesh`, ...).
    pub fn two_stage(&self, law: Law) -> anyhow::Result<TwoStageOptions> {
        let mut o = TwoStageOptions::new(law);
        if let Some(s) = &self.stages {
            o.stages = TwoStageOptions::parse_stages(s)?;
        }
        if let Some(n) = self.prony_terms {
            o.set_terms(n)
                .map_err(|e| anyhow::anyhow!("--prony-terms {n}: {e}"))?;
        }
        if let Some(h) = self.fit_mesh {
            o.set_fit_mesh(h)
                .map_err(|e| anyhow::anyhow!("--fit-mesh {h}: {e}"))?;
        }
        if let Some(h) = self.correct_mesh {
            o.set_correct_mesh(h)
                .map_err(|e| anyhow::anyhow!("--correct-mesh {h}: {e}"))?;
        }
        if let Some(dt) = self.time_step {
            o.set_time_step(dt)
                .map_err(|e| anyhow::anyhow!("--time-step {dt}: {e}"))?;
        }
        if let Some(rho) = self.edge_radius {
            o.set_edge_radius(rho)
                .map_err(|e| anyhow::anyhow!("--edge-radius {rho}: {e}"))?;
        }
        if let Some(rho) = self.fit_edge_radius {
            o.set_fit_edge_radius(rho)
                .map_err(|e| anyhow::anyhow!("--fit-edge-radius {rho}: {e}"))?;
        }
        if let Some(h) = self.mesh_check {
            o.set_mesh_check(h)
                .map_err(|e| anyhow::anyhow!("--mesh-check {h}: {e}"))?;
        }
        o.one_stage = self.compare;
        o.profile = self.profile;
        Ok(o)
    }
}

/// The Q1 record `data`: `FILE` or `Q1=FILE` (columns time_s,
/// displacement_mm, force_N), or `<array:K>` for `arrays[K]`.
pub fn q1_record(data: &str, arrays: &[ArrayRecord]) -> anyhow::Result<Q1Record> {
    let path = data
        .split_once('=')
        .filter(|(t, _)| t.eq_ignore_ascii_case("q1"))
        .map_or(data, |(_, p)| p);
    let Some(r) = record_for(path, arrays)? else {
        return Q1Record::read(Path::new(path));
    };
    let d = TestData::from_table(
        "Q1",
        TestKind::N1,
        r.table("Q1 arrays")?,
        ReadOptions::default(),
    )?;
    let time = d.loading.time.clone().ok_or_else(|| {
        anyhow::anyhow!("Q1 arrays: a Q1 record is a timed ramp-and-hold: it needs a time_s column")
    })?;
    Q1Record::new("Q1 arrays", time, d.loading.drive.clone(), d.observed)
}

/// Runs the staged identification of `record` (stages, polish, the
/// options' checks and comparisons), its progress lines to `observer`.
pub fn identify_q1(
    record: &Q1Record,
    options: &TwoStageOptions,
    observer: &(dyn Observer + Sync),
) -> anyhow::Result<TwoStageResult> {
    let say = |s: &str| observer.message(s);
    identify(record, options, &say)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_are_checked_naming_the_command_lines_option() {
        let e = |o: Q1Options| o.for_law("neo-hookean").unwrap_err().to_string();
        let m = e(Q1Options {
            fit_mesh: Some(-1.0),
            ..Default::default()
        });
        assert!(m.starts_with("--fit-mesh -1: "), "{m}");
        let m = e(Q1Options {
            prony_terms: Some(0),
            ..Default::default()
        });
        assert!(m.starts_with("--prony-terms 0: "), "{m}");
        let m = e(Q1Options {
            stages: Some("plastic".into()),
            ..Default::default()
        });
        assert!(m.contains("plastic"), "{m}");
        let m = Q1Options::default()
            .for_law("hooke")
            .unwrap_err()
            .to_string();
        assert!(m.starts_with("--law hooke: "), "{m}");
        let o = Q1Options {
            compare: true,
            time_step: Some(0.5),
            ..Default::default()
        }
        .for_law("neo-hookean")
        .unwrap();
        assert!(o.one_stage && !o.profile && o.max_time_step == 0.5);
    }

    #[test]
    fn a_record_from_arrays_needs_times_and_a_hold() {
        let (d, f) = (vec![0.0, 0.5, 1.0], vec![0.0, 0.1, 0.3]);
        let arrays = [ArrayRecord {
            names: vec!["displacement_mm".into(), "force_N".into()],
            columns: vec![&d, &f],
        }];
        let m = q1_record("<array:0>", &arrays).unwrap_err().to_string();
        assert!(m.contains("it needs a time_s column"), "{m}");
        let t = vec![0.0, 0.5, 1.0, 2.0];
        let (d, f) = (vec![0.0, 0.5, 1.0, 1.0], vec![0.0, 0.1, 0.3, 0.25]);
        let arrays = [ArrayRecord {
            names: vec!["time_s".into(), "displacement_mm".into(), "force_N".into()],
            columns: vec![&t, &d, &f],
        }];
        let r = q1_record("Q1=<array:0>", &arrays).unwrap();
        assert_eq!((r.ramp_end(), r.force.len()), (2, 4));
    }
}
