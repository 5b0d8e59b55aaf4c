//! Unit tests of the sampling API.

use super::*;
use crate::api::Silent;

/// The C1 record of docs/validation (reduced polynomial of order 2).
fn c1_record() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../docs/validation/mcmc_c1_rp2_data.csv")
        .display()
        .to_string()
}

fn c1_options() -> SampleOptions {
    SampleOptions {
        benchmark: Some("C1".into()),
        sampler: SamplerKind::Demc,
        draws: Some(100),
        max_draws: Some(100),
        tune: Some(100),
        parallel: Some(1),
        seed: 3,
        ..SampleOptions::new("reduced-polynomial:2", vec![c1_record()])
    }
}

#[test]
fn samples_a_c1_record_into_draws_a_table_and_a_report() {
    let s = sample(&c1_options(), &[], &Silent).unwrap();
    assert_eq!(s.names, ["C10", "C20", "sigma"]);
    let (c, d) = (s.chains.n_chains, s.chains.n_draws);
    assert_eq!(d, 100);
    assert_eq!(s.chains.values.len(), c * d * s.names.len());
    assert_eq!(s.summary.len(), 3);
    assert_eq!(s.report["params"]["C10"]["mean"], json!(s.summary[0].mean));
    assert_eq!(s.report["law"], "reduced-polynomial:2");
    assert!(s.table.starts_with("demc on C1 compression"), "{}", s.table);
    assert!(s.table.contains("posterior correlation:"), "{}", s.table);
    let c10 = s.summary[0].mean;
    assert!((c10 / 6.8e-4 - 1.0).abs() < 0.05, "{c10}");
    // 100 draws cannot reach ESS 400: the warning is in the result, not printed
    assert!(!s.converged);
    assert!(
        s.warnings[0].starts_with("warning: not converged"),
        "{:?}",
        s.warnings
    );
}

#[test]
fn the_evidence_is_added_to_the_table_and_the_report() {
    let o = SampleOptions {
        priors: vec!["C10=lognormal:-7.3,1".into(), "C20=normal:0,1".into()],
        evidence: true,
        ..c1_options()
    };
    let s = sample(&o, &[], &Silent).unwrap();
    let ti = s.report["thermodynamic_integration"]["log_evidence"]
        .as_f64()
        .unwrap();
    assert!(ti.is_finite());
    assert_eq!(s.report["thermodynamic_integration"]["rungs"], 20);
    let last = s.table.lines().last().unwrap();
    assert!(
        last.starts_with("log evidence: thermodynamic integration"),
        "{last}"
    );
    assert!(s.report["laplace"]["evidence_meaningful"]
        .as_bool()
        .unwrap());
}

#[test]
fn a_record_given_as_arrays_samples_as_its_file() {
    let text = std::fs::read_to_string(c1_record()).unwrap();
    let (mut d, mut f) = (Vec::new(), Vec::new());
    for line in text.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let mut cells = line.split(',').map(|c| c.trim().parse::<f64>().unwrap());
        d.push(cells.next().unwrap());
        f.push(cells.next().unwrap());
    }
    let arrays = [ArrayRecord {
        names: vec!["displacement_mm".into(), "force_N".into()],
        columns: vec![&d, &f],
    }];
    let o = SampleOptions {
        data: vec!["<array:0>".into()],
        ..c1_options()
    };
    let a = sample(&o, &arrays, &Silent).unwrap();
    let b = sample(&c1_options(), &[], &Silent).unwrap();
    assert_eq!(a.chains.values, b.chains.values);
}

#[test]
fn bad_options_are_named_before_any_work() {
    let e = |o: SampleOptions| prepare(&o, &[]).err().unwrap().to_string();
    assert_eq!(
        "gibbs".parse::<SamplerKind>().unwrap_err().to_string(),
        "--sampler gibbs: expected ensemble, demc or nuts"
    );
    assert_eq!("NUTS".parse::<SamplerKind>().unwrap(), SamplerKind::Nuts);
    let m = e(SampleOptions {
        mesh: Some("fine".into()),
        ..c1_options()
    });
    assert!(
        m.starts_with("--mesh: an option of --benchmark N1, N3, Q1"),
        "{m}"
    );
    let m = e(SampleOptions {
        draws: Some(2),
        ..c1_options()
    });
    assert!(m.contains("at least 4 draws"), "{m}");
    let m = e(SampleOptions {
        sigma: Some(-1.0),
        ..c1_options()
    });
    assert!(
        m.starts_with("--sigma -1: must be a positive number"),
        "{m}"
    );
    let m = e(SampleOptions {
        law: None,
        ..c1_options()
    });
    assert!(m.starts_with("--law: give the material law"), "{m}");
    let m = e(SampleOptions {
        benchmark: Some("Q1".into()),
        ar1: true,
        ..c1_options()
    });
    assert!(m.contains("leave out --ar1 with --benchmark Q1"), "{m}");
}

#[test]
fn priors_are_checked_by_name() {
    let run = |priors: &[&str], evidence: bool| {
        let o = SampleOptions {
            priors: priors.iter().map(|p| p.to_string()).collect(),
            evidence,
            ..c1_options()
        };
        sample(&o, &[], &Silent).err().unwrap().to_string()
    };
    let m = run(&["C10=flat", "C10=normal:0,1"], false);
    assert!(m.contains("a prior for C10 is given twice"), "{m}");
    let m = run(&["C30=flat"], false);
    assert!(m.contains("unknown parameter `C30`"), "{m}");
    let m = run(&["C10"], false);
    assert!(m.starts_with("--prior C10: expected NAME=SPEC"), "{m}");
    let m = run(&["C10=flat"], true);
    assert!(m.contains("--evidence needs a proper prior"), "{m}");
}

#[test]
fn a_q1_record_without_times_is_refused_naming_the_column() {
    let (d, f) = (vec![0.0, 0.5, 1.0], vec![0.0, 0.1, 0.3]);
    let arrays = [ArrayRecord {
        names: vec!["displacement_mm".into(), "force_N".into()],
        columns: vec![&d, &f],
    }];
    let o = SampleOptions {
        benchmark: Some("Q1".into()),
        data: vec!["<array:0>".into()],
        boxes: vec!["C10=0.001,0.01".into()],
        ..SampleOptions::new("neo-hookean", vec![])
    };
    let m = prepare(&o, &arrays).err().unwrap().to_string();
    assert!(m.contains("it needs a time_s column"), "{m}");
}
