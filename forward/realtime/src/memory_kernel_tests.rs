//! Tests of the real-time model's fitted memory ([`super`]).

use super::*;

/// Histories for the tests: a ramp and hold, and random ones.
fn histories(depth_max: f64, n: usize) -> Vec<History> {
    let mut h = vec![History::from_knots(
        vec![(0.0, 0.0), (1.0, depth_max), (6.0, depth_max)],
        1e-2,
    )];
    for k in 1..n {
        h.push(crate::random_history(500 + k as u64, depth_max, 5, 1e-2));
    }
    h
}

/// Stations every 0.1 s of a force computed on the history's samples.
fn stations(h: &History, force: &[f64]) -> Vec<(f64, f64)> {
    h.time
        .iter()
        .zip(force)
        .step_by(10)
        .map(|(&t, &f)| (t, f))
        .collect()
}

/// A kernel the fit can represent: a quadratic equilibrium force, the
/// memory of mode `i` `[0.3, 0.2][i]` times it, read `deep` times as
/// strongly at the deepest present depth as at 0.
fn representable(dmax: f64, knots: usize, taus: &[f64], lift_off: bool, deep: f64) -> MemoryKernel {
    let mut k = MemoryKernel::shape(dmax, knots, taus, lift_off);
    for j in 0..knots {
        let x = dmax * (j + 1) as f64 / knots as f64;
        k.equilibrium[j] = 0.5 * x + 0.2 * x * x;
        for i in 0..taus.len() {
            let base = (i * knots + j) * PRESENT;
            k.memory[base] = [0.3, 0.2][i] * k.equilibrium[j];
            k.memory[base + 1] = deep * k.memory[base];
        }
    }
    k
}

/// `truth`'s stations on `hs`, and the kernel fitted to the first 8.
fn fit_to(
    truth: &mut MemoryKernel,
    hs: &[History],
    taus: &[f64],
) -> (MemoryKernel, Vec<Vec<(f64, f64)>>) {
    let st: Vec<Vec<(f64, f64)>> = hs.iter().map(|h| stations(h, &truth.run(h).0)).collect();
    let runs: Vec<TrainingRun<'_>> = hs[..8]
        .iter()
        .zip(&st)
        .map(|(history, s)| TrainingRun {
            history,
            stations: s,
        })
        .collect();
    let fit = MemoryKernel::fit(truth.depth_max, truth.knots, taus, &runs).unwrap();
    (fit, st)
}

/// The largest error of `fit` over the histories after the first 8 (those
/// it was not fitted to).
fn worst_held_out(fit: &mut MemoryKernel, hs: &[History], st: &[Vec<(f64, f64)>]) -> f64 {
    hs[8..]
        .iter()
        .zip(&st[8..])
        .map(|(history, stations)| fit.max_relative_error(&TrainingRun { history, stations }))
        .fold(0.0, f64::max)
}

/// A kernel whose force is exactly representable: the fit recovers it
/// (coefficients reproduce the force on unseen histories), and the
/// cross-validation picks the loss-of-contact form it was made with.
#[test]
fn recovers_a_kernel_it_can_represent() {
    let (dmax, knots) = (2.0, 6);
    let taus = [0.3, 4.0];
    for lift_off in [false, true] {
        // the memory reads 40 % stronger at the deepest present depth
        let mut truth = representable(dmax, knots, &taus, lift_off, 1.4);
        let hs = histories(dmax, 12);
        let (mut fit, st) = fit_to(&mut truth, &hs, &taus);
        assert_eq!(
            fit.lift_off, lift_off,
            "cv {:?}",
            fit.training.cv_max_relative_error
        );
        let e = worst_held_out(&mut fit, &hs, &st);
        assert!(e < 2e-3, "lift_off {lift_off}: held-out error {e}");
    }
}

/// The compliant contact: deep in contact it answers as the hard one
/// (the gap is `~ A g0 / F`), on a withdrawal its force fades to 0 where
/// the hard one's stops at once, and a vanishing `g0` is the hard
/// contact.
#[test]
fn a_compliant_contact_fades_where_the_hard_one_lets_go() {
    let (dmax, knots) = (2.0, 8);
    let prony = [(0.3, 0.5), (0.2, 10.0)];
    let elastic: Vec<f64> = (1..=knots)
        .map(|k| {
            let x = dmax * k as f64 / knots as f64;
            x + 0.5 * x * x
        })
        .collect();
    let hard = MemoryKernel::qlv(dmax, &elastic, &prony, true);
    // a ramp to 2 mm in 0.5 s, a hold, a withdrawal in 0.2 s
    let h = History::from_knots(
        vec![(0.0, 0.0), (0.5, 2.0), (1.5, 2.0), (1.7, 0.0), (3.0, 0.0)],
        1e-3,
    );
    let run = |k: &MemoryKernel| {
        let mut k = k.clone();
        k.run(&h)
    };
    let (fh, _) = run(&hard);
    let peak = fh.iter().copied().fold(0.0, f64::max);
    let mut soft = hard.clone();
    soft.soft_contact = [0.1 * dmax, 0.03 * peak];
    let (fs, es) = run(&soft);
    let at = |t: f64| h.sample_at(t);
    // at the end of the ramp and the hold: within 1 % of the peak
    for t in [0.5, 1.5] {
        let (a, b) = (fh[at(t)], fs[at(t)]);
        assert!(
            (a - b).abs() < 0.01 * peak,
            "t {t}: hard {a}, compliant {b}"
        );
        assert!(es[at(t)] > h.depth[at(t)], "the surface lags by a gap");
    }
    // the hard contact lets go during the withdrawal; the compliant one
    // still presses there, less than at the start of the withdrawal
    let gone = (at(1.5)..at(1.7))
        .find(|&j| fh[j] == 0.0)
        .expect("the hard contact lets go before the punch is out");
    assert!(
        fs[gone] > 0.0 && fs[gone] < fs[at(1.5)],
        "compliant {} where the hard one is 0",
        fs[gone]
    );
    // and no jump: the largest change of a 1 ms sample is small
    let jump = fs
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f64::max);
    assert!(jump < 0.02 * peak, "largest 1 ms change {jump} N");
    // at the surface after the withdrawal and at rest, no force; and it
    // goes to 0 with the depth
    assert_eq!(*fs.last().unwrap(), 0.0);
    let mut rest = soft.clone();
    rest.reset();
    assert_eq!(
        rest.step(0.0, 1e-3).0,
        0.0,
        "a force at the surface at rest"
    );
    let tiny = rest.step(1e-4, 1e-3).0;
    assert!(tiny > 0.0 && tiny < 1e-3 * peak, "at 1e-4 mm: {tiny} N");
    // a vanishing g0 is the hard contact
    let mut thin = hard.clone();
    thin.soft_contact = [1e-9 * dmax, 0.03 * peak];
    let (ft, _) = run(&thin);
    let worst = ft
        .iter()
        .zip(&fh)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(
        worst < 1e-3 * peak,
        "g0 -> 0 differs from the hard contact by {worst} N"
    );
    let mut bad = hard.clone();
    bad.soft_contact = [f64::NAN, 1.0];
    assert!(bad.check().unwrap_err().contains("compliant contact"));
}

/// Data made with a compliant contact: the cross-validation chooses a
/// compliant form, and the fit reproduces unseen histories.
#[test]
fn the_cross_validation_finds_a_compliant_contact() {
    let (dmax, knots) = (2.0, 6);
    let taus = [0.3, 4.0];
    let mut truth = representable(dmax, knots, &taus, true, 1.0);
    let hs = histories(dmax, 12);
    // the compliant form [0.1, 0.1] of COMPLIANT at the data's peak
    let p = hs.iter().flat_map(|h| truth.run(h).0).fold(0.0, f64::max);
    truth.soft_contact = [0.1 * dmax, 0.1 * p];
    let (mut fit, st) = fit_to(&mut truth, &hs, &taus);
    let cv = fit.training.cv_contacts.clone();
    assert!(
        fit.lift_off && fit.soft_contact[0] > 0.0,
        "chose {:?}; cv {cv:?}",
        fit.soft_contact
    );
    assert!(
        cv[0].1 > 2.0 * cv[3].1,
        "hard against the truth's form: {cv:?}"
    );
    let e = worst_held_out(&mut fit, &hs, &st);
    assert!(e < 1e-2, "held-out error {e}; cv {cv:?}");
}

/// The special case that is QLV: the same forces as the product's QLV.
#[test]
fn qlv_coefficients_answer_as_qlv() {
    use crate::{MonotoneCubic, RealTimeModel};
    let (dmax, knots) = (1.0, 10);
    let prony = vec![(0.3, 0.5), (0.2, 10.0)];
    let x: Vec<f64> = (0..=knots)
        .map(|k| dmax * k as f64 / knots as f64)
        .collect();
    // an elastic curve linear between the knots, so the hats are exact
    let y: Vec<f64> = x.iter().map(|d| 2.0 * d).collect();
    let mut qlv = RealTimeModel::new(
        "q".into(),
        MonotoneCubic::new(x.clone(), y.clone()).unwrap(),
        prony.clone(),
    )
    .unwrap();
    let mut k = MemoryKernel::qlv(dmax, &y[1..], &prony, true);
    let h = crate::random_history(3, dmax, 6, 1e-3);
    let a = qlv.run(&h.time, &h.depth).unwrap();
    let (b, _) = k.run(&h);
    let worst = a
        .iter()
        .zip(&b)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-9, "largest difference {worst} N");
    assert!(a.contains(&0.0), "the history should lose contact");
}

#[test]
fn refuses_bad_input() {
    let h = histories(1.0, 2);
    let st = vec![(0.5, 1.0)];
    let runs: Vec<TrainingRun<'_>> = h
        .iter()
        .map(|history| TrainingRun {
            history,
            stations: &st,
        })
        .collect();
    let e = MemoryKernel::fit(1.0, 8, &[1.0], &runs).unwrap_err();
    assert!(e.contains("at least 5"), "{e}");
    let e = MemoryKernel::fit(1.0, 2, &[1.0], &runs).unwrap_err();
    assert!(e.contains("at least 3 knots"), "{e}");
    let e = MemoryKernel::fit(1.0, 8, &[0.0], &runs).unwrap_err();
    assert!(e.contains("time constant"), "{e}");
    let mut k = MemoryKernel::shape(1.0, 8, &[1.0], false);
    k.memory.pop();
    assert!(k.check().unwrap_err().contains("memory coefficients"));
}

/// A stop operator alone: on a ramp its stretch follows the depth until it
/// reaches its threshold `r`, then stays; on the way back it falls by `2 r`
/// over `2 r` of depth: the force `b s` (read at the present depth as
/// `b0 (1 - e/D) + b1 e/D`) is the elastic-perfectly-plastic element's,
/// a rate-independent hysteresis loop.
#[test]
fn a_stop_operator_is_an_elastic_plastic_element() {
    let (dmax, r, b) = (2.0, 0.1, 3.0);
    let mut k = MemoryKernel::shape(dmax, 4, &[1.0], false);
    k.stops = vec![r];
    k.stop_coefficients = vec![b, b];
    k.check().unwrap();
    k.reset();
    // in and out in 0.01 mm steps (no memory, no equilibrium: the force is
    // the stop's alone)
    let path: Vec<f64> = (0..=100)
        .chain((0..=100).rev())
        .map(|j| j as f64 * 0.01)
        .collect();
    let f: Vec<f64> = path.iter().map(|&d| k.step(d, 1e-3).0).collect();
    let want = |i: usize| {
        let d = path[i];
        if i <= 100 {
            b * d.min(r)
        } else {
            // from +r at 1 mm down by the depth withdrawn
            b * (r - (1.0 - d)).max(-r)
        }
    };
    for (i, &fi) in f.iter().enumerate() {
        // the force is clamped at 0 with the surface following the punch
        let w = want(i).max(0.0);
        assert!(
            (fi - w).abs() < 1e-12,
            "sample {i}, depth {}: {fi} against {w}",
            path[i]
        );
    }
    // a loop: at 0.5 mm b r on the way in, -b r (clamped at 0) on the way out
    assert!((f[50] - b * r).abs() < 1e-12 && f[150] == 0.0);
    let mut bad = k.clone();
    bad.stop_coefficients.pop();
    assert!(bad.check().unwrap_err().contains("stop operators"));
    bad = k.clone();
    bad.stops[0] = 0.0;
    assert!(bad.check().unwrap_err().contains("stop operators"));
}

/// Data made with stop operators on top of a representable memory: the
/// cross-validation chooses them, and the fit reproduces unseen
/// histories; without them the held-out error is far larger.
#[test]
fn the_cross_validation_finds_the_stop_operators() {
    let (dmax, knots) = (2.0, 6);
    let taus = [0.3, 4.0];
    let mut truth = representable(dmax, knots, &taus, false, 1.0);
    truth.stops = STOPS.iter().map(|r| r * dmax).collect();
    // the stops carry up to sum b_j1 r_j = 0.24 N at 2 mm, where the
    // equilibrium force is 1.8 N
    truth.stop_coefficients = vec![0.3, 0.6, 0.2, 0.4, 0.1, 0.2];
    truth.reset();
    let hs = histories(dmax, 12);
    let (mut fit, st) = fit_to(&mut truth, &hs, &taus);
    let cv = fit.training.cv_stops.clone();
    assert_eq!(fit.stops.len(), STOPS.len(), "cv with the stops {cv:?}");
    assert!(
        fit.training.cv_max_relative_error.unwrap()[0] > 5.0 * cv[0],
        "following the punch without and with the stops: {:?} {cv:?}",
        fit.training.cv_max_relative_error
    );
    let e = worst_held_out(&mut fit, &hs, &st);
    assert!(e < 2e-3, "held-out error {e}; cv {cv:?}");
}
