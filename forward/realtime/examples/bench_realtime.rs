//! The real-time model's time per sample and held-out error table, and the
//! generator of `docs/validation/realtime.md`.
//!
//! `cargo run --release -p palpate-realtime --example bench_realtime -- MODEL.json`
//! prints the time per sample (2e6 samples of a 1 kHz random history of
//! ramps, holds and unloadings, on one thread) and the held-out error table
//! of a stored model (as `palpate realtime build` writes it).
//!
//! `cargo run --release -p palpate-realtime --example bench_realtime -- --page docs/validation/realtime.md [ID ...]`
//! builds the page's models from the FE models (the builds of [`BUILDS`],
//! or those named by ID; minutes each, one at a time), measures each, and
//! rewrites the page's table: the rows of the builds run are replaced, the
//! others kept, and the rest of the page is left as it is.

use palpate_core::ForwardModel;
use palpate_fe::{N1Needle, Prony, Q1Punch};
use palpate_realtime::report::contact_words;
use palpate_realtime::{random_history, RealTimeModel, RealTimeRequest};
use std::time::{SystemTime, UNIX_EPOCH};

/// The material of every build: neo-Hookean, C10 (MPa).
const C10: f64 = 0.0016;
/// Its Prony series.
const PRONY: &str = "g1=0.3,tau1=0.5,g2=0.2,tau2=10";
/// Training and held-out histories, segments per held-out history (the
/// command's defaults).
const TRAIN: usize = 12;
const HOLDOUT: usize = 4;
const SEGMENTS: usize = 6;
/// The target a row is read against (largest held-out error over the peak, %).
const TARGET: f64 = 2.0;
/// Samples timed per model.
const SAMPLES: usize = 2_000_000;
/// The lines that enclose the generated table in the page.
const BEGIN: &str = "<!-- bench_realtime: table begins; generated, do not edit -->";
const END: &str = "<!-- bench_realtime: table ends -->";

/// One build of the page: its id, its benchmark and the options of
/// `palpate realtime build` that differ from the defaults.
struct Build {
    id: &'static str,
    benchmark: &'static str,
    depth_max: f64,
    edge_radius: Option<f64>,
    friction: Option<f64>,
    mesh: usize,
}

/// The page's builds, in its order.
const BUILDS: [Build; 9] = [
    q1("q1-edge0.2-1mm", 1.0, None, 1),
    q1("q1-edge1-4mm", 4.0, Some(1.0), 1),
    q1("q1-edge1-5mm", 5.0, Some(1.0), 1),
    q1("q1-edge0.2-5mm-mesh2", 5.0, None, 2),
    n1("n1-mu0-4mm", 4.0, 0.0),
    n1("n1-mu0-10mm", 10.0, 0.0),
    n1("n1-mu0.8-3mm", 3.0, 0.8),
    n1("n1-mu0.8-4mm", 4.0, 0.8),
    n1("n1-mu0.8-10mm", 10.0, 0.8),
];

const fn q1(id: &'static str, depth_max: f64, edge_radius: Option<f64>, mesh: usize) -> Build {
    Build {
        id,
        benchmark: "Q1",
        depth_max,
        edge_radius,
        friction: None,
        mesh,
    }
}

const fn n1(id: &'static str, depth_max: f64, friction: f64) -> Build {
    Build {
        id,
        benchmark: "N1",
        depth_max,
        edge_radius: None,
        friction: Some(friction),
        mesh: 1,
    }
}

impl Build {
    /// The options of `palpate realtime build` besides the material's.
    fn options(&self) -> String {
        let mut o = format!(
            "--benchmark {} --depth-max {}",
            self.benchmark, self.depth_max
        );
        if let Some(r) = self.edge_radius {
            o += &format!(" --edge-radius {r}");
        }
        if let Some(mu) = self.friction {
            o += &format!(" --friction {mu}");
        }
        if self.mesh != 1 {
            o += &format!(" --mesh {}", self.mesh);
        }
        o
    }

    /// The elastic and viscoelastic FE models, as `palpate realtime build`
    /// makes them.
    fn models(&self, prony: &Prony) -> (Box<dyn ForwardModel>, Box<dyn ForwardModel>) {
        let law = "neo-hookean".parse().expect("a law");
        if self.benchmark == "Q1" {
            let mut e = Q1Punch::new(law);
            e.level = self.mesh;
            if let Some(r) = self.edge_radius {
                e.set_edge_radius(r).expect("an edge radius");
            }
            let mut v = e.clone();
            v.prony = Some(prony.clone());
            (Box::new(e), Box::new(v))
        } else {
            let mut e = N1Needle::new(law);
            e.mesh.level = self.mesh;
            e.friction = self.friction.unwrap_or(0.8);
            let mut v = e.clone();
            v.prony = Some(prony.clone());
            (Box::new(e), Box::new(v))
        }
    }

    /// Builds the model from the FE runs.
    fn run(&self) -> Result<RealTimeModel, String> {
        let prony: Prony = PRONY.parse().map_err(|e| format!("{e}"))?;
        let (elastic, visco) = self.models(&prony);
        let theta = |m: &dyn ForwardModel| -> Vec<f64> {
            let mut t = vec![C10];
            t.extend(m.space().params[1..].iter().map(|p| p.initial));
            t
        };
        let (te, tv) = (theta(elastic.as_ref()), theta(visco.as_ref()));
        let req = RealTimeRequest {
            elastic: elastic.as_ref(),
            elastic_theta: &te,
            viscoelastic: visco.as_ref(),
            viscoelastic_theta: &tv,
            prony: prony.terms().to_vec(),
            depth_max: self.depth_max,
            knots: 20,
            validation_histories: HOLDOUT,
            segments: SEGMENTS,
            training_histories: TRAIN,
            kernel_knots: 10,
        };
        let tick = |done: usize, total: usize| eprint!("\r{}: {done}/{total} FE runs", self.id);
        let m = RealTimeModel::build(&req, Some(&tick));
        eprintln!();
        m
    }
}

/// Seconds per sample of `m` on a 1 kHz random history, and a checksum.
fn time_per_sample(m: &mut RealTimeModel) -> (f64, f64) {
    let h = random_history(7, m.depth_max, 400, 1e-3);
    m.reset();
    let t0 = std::time::Instant::now();
    let mut sum = 0.0;
    let mut k = 0;
    for _ in 0..SAMPLES {
        sum += m.force(h.depth[k], 1e-3).expect("in range");
        k = (k + 1) % h.depth.len();
    }
    (t0.elapsed().as_secs_f64() / SAMPLES as f64, sum)
}

fn time_words(per: f64) -> String {
    if per < 1e-6 {
        format!("{:.0} ns", per * 1e9)
    } else {
        format!("{:.2} us", per * 1e6)
    }
}

/// The page's table header.
fn header() -> String {
    "| id | build (`palpate realtime build` options) | held-out max error / peak, per history | RMS error / peak | within 2 % | memory | time per sample (one core) | build time | measured (date, commit, machine) |\n|---|---|---|---|---|---|---|---|---|".into()
}

/// The page's row of a model built as `b`.
fn row(b: &Build, m: &RealTimeModel, per: f64, measured: &str) -> String {
    let pct = |x: f64| format!("{:.2}", 100.0 * x);
    let max: Vec<String> = m
        .validation
        .iter()
        .map(|v| pct(v.max_relative_error))
        .collect();
    let rms: Vec<f64> = m
        .validation
        .iter()
        .filter_map(|v| v.rms_relative_error)
        .collect();
    let rms = match (
        rms.iter().copied().reduce(f64::min),
        rms.iter().copied().reduce(f64::max),
    ) {
        (Some(lo), Some(hi)) => format!("{}-{} %", pct(lo), pct(hi)),
        _ => "-".into(),
    };
    let within = m
        .validation
        .iter()
        .all(|v| 100.0 * v.max_relative_error <= TARGET);
    let mut left_out = String::new();
    if !m.validation_failures.is_empty() || !m.training_failures.is_empty() {
        left_out = format!(
            " ({} training and {} held-out histories the FE did not finish, left out)",
            m.training_failures.len(),
            m.validation_failures.len()
        );
    }
    let memory = m
        .kernel
        .as_ref()
        .map_or("plain QLV".to_string(), contact_words);
    format!(
        "| {} | `{}` | {} %{left_out} | {rms} | {} | {memory} | {} | {:.0} s | {measured} |",
        b.id,
        b.options(),
        max.join(" / "),
        if within { "yes" } else { "no" },
        time_words(per),
        m.build_time_s,
    )
}

/// Today's date (UTC), the commit (`-dirty` with local changes) and the
/// machine's cores.
fn measured() -> String {
    let days = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs() / 86_400) as i64;
    // civil from days (H. Hinnant's algorithm)
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    let git = |args: &[&str]| {
        std::process::Command::new("git")
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    let commit = git(&["rev-parse", "--short=7", "HEAD"]).unwrap_or_else(|| "unknown".into());
    let dirty =
        git(&["status", "--porcelain", "--untracked-files=no"]).is_some_and(|s| !s.is_empty());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    format!(
        "{y}-{m:02}-{d:02}, {commit}{}, {cores} cores",
        if dirty { "-dirty" } else { "" }
    )
}

/// The page with the rows of `new` (id, row) in place of the old ones of
/// the same ids; every build's row in [`BUILDS`] order, then rows of other
/// ids as they were.
fn rewrite(page: &str, new: &[(String, String)]) -> Result<String, String> {
    let (before, rest) = page
        .split_once(BEGIN)
        .ok_or_else(|| format!("the page has no line `{BEGIN}`"))?;
    let (table, after) = rest
        .split_once(END)
        .ok_or_else(|| format!("the page has no line `{END}`"))?;
    let id_of = |l: &str| l.split('|').nth(1).map(|c| c.trim().to_string());
    let mut rows: Vec<(String, String)> = table
        .lines()
        .filter(|l| l.starts_with('|') && !l.starts_with("| id ") && !l.starts_with("|---"))
        .filter_map(|l| id_of(l).map(|id| (id, l.to_string())))
        .collect();
    for (id, r) in new {
        match rows.iter_mut().find(|(i, _)| i == id) {
            Some(old) => old.1 = r.clone(),
            None => rows.push((id.clone(), r.clone())),
        }
    }
    let order = |id: &str| {
        BUILDS
            .iter()
            .position(|b| b.id == id)
            .unwrap_or(BUILDS.len())
    };
    rows.sort_by_key(|(id, _)| order(id));
    let body: Vec<String> = rows.into_iter().map(|(_, r)| r).collect();
    Ok(format!(
        "{before}{BEGIN}\n{}\n{}\n{END}{after}",
        header(),
        body.join("\n")
    ))
}

fn page(path: &str, ids: &[String]) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    if let Some(bad) = ids.iter().find(|id| !BUILDS.iter().any(|b| &b.id == id)) {
        let known: Vec<&str> = BUILDS.iter().map(|b| b.id).collect();
        panic!("no build `{bad}` (the page's builds: {})", known.join(", "));
    }
    let measured = measured();
    let mut rows = Vec::new();
    for b in BUILDS
        .iter()
        .filter(|b| ids.is_empty() || ids.iter().any(|i| i == b.id))
    {
        match b.run() {
            Ok(mut m) => {
                let (per, sum) = time_per_sample(&mut m);
                eprintln!("(checksum {sum:.3e})");
                let r = row(b, &m, per, &measured);
                println!("{r}");
                rows.push((b.id.to_string(), r));
            }
            Err(e) => eprintln!("{}: the build failed, its row is kept: {e}", b.id),
        }
        // each row as soon as it is measured: a later build may take an hour
        let out = rewrite(&text, &rows).unwrap_or_else(|e| panic!("{path}: {e}"));
        std::fs::write(path, out).unwrap_or_else(|e| panic!("{path}: {e}"));
    }
    eprintln!("wrote {path}");
}

fn one(path: &str) {
    let text = std::fs::read_to_string(path).expect("read the model");
    let mut s = RealTimeModel::from_json(&text).expect("a real-time model");
    let (per, sum) = time_per_sample(&mut s);
    println!("{}", s.model);
    match &s.kernel {
        Some(k) => println!(
            "memory kernel: {} knots, {} time constants; on loss of contact it {}",
            k.knots,
            k.taus.len(),
            contact_words(k)
        ),
        None => println!("plain QLV on the force curve"),
    }
    println!(
        "| samples | time per sample | rate (one core) | target |\n|---|---|---|---|\n| {SAMPLES} | {} | {:.1} MHz | 10 us (1 kHz needs 1 ms) |\n",
        time_words(per),
        1e-6 / per
    );
    println!("{}", palpate_realtime::report::error_table(&s));
    eprintln!("(checksum {sum:.3e})");
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("--page") => {
            let path = args
                .get(1)
                .expect("usage: bench_realtime --page PAGE.md [ID ...]");
            page(path, &args[2..]);
        }
        Some(path) => one(path),
        None => panic!("usage: bench_realtime MODEL.json | --page PAGE.md [ID ...]"),
    }
}
