//! `palpate calibrate`: fit a hyperelastic law to homogeneous-test data or a
//! C1 force record, print a table, optionally write JSON and an SVG plot.

use crate::model::calibration::Calibration;
use crate::model::ExperimentSpec;
use crate::records::arrays::ArrayRecord;
pub use crate::records::data_option::{
    read_data, read_data_opts, read_data_with, read_force_records, split_data, split_data_with,
    split_pair,
};
use crate::records::TestData;
use crate::report::{calibration_table, fit_plot};
use crate::run::output::{write_atomic, write_json};
use palpate_material::Law;
use std::path::Path;
use std::path::PathBuf;

/// Fit a hyperelastic law to homogeneous-test data or to a C1 force record
///
/// Homogeneous tests: `--data TEST=FILE` with TEST one of
///   uniaxial       stretch (or strain, true_strain), stress_MPa; tension and compression
///   biaxial        equibiaxial: stretch, stress_MPa; general (Kawabata): lambda1,
///                  lambda2, stress1_MPa, stress2_MPa
///   planar         pure shear: stretch, stress_MPa
///   simple_shear   amount_of_shear, shear_stress_MPa
/// Stresses are nominal (force / undeformed area) unless the column says
/// true_ (Cauchy), e.g. true_stress_MPa; units MPa, kPa or Pa in the name.
/// A time_s column makes the record timed (for --viscoelastic).
/// Options of one record go in brackets before `=`:
///   --data 'simple_shear[axial_stretch=0.9,weight=0.5]=FILE'
/// (weight: of the record in a joint fit; axial_stretch: shear superposed on
/// an axial stretch; stress_unit=kPa: the file's stresses are in kPa whatever
/// its header says). Several --data options are fitted jointly with one
/// parameter set.
///
/// Benchmark C1 (38 x 9 mm cylinder between lubricated platens):
/// `--benchmark C1 --data FILE` with columns `displacement_mm,force_N`.
///
/// A lab's own experiment (docs/guide/experiment.md): `--experiment FILE
/// --data RECORD` fits the description's fitted parameters by finite
/// elements (its fixed ones held), the record's columns `displacement_mm,
/// force_N`. `--benchmark N1` (or N3) is the preset of that name: `palpate
/// experiment show N1` prints it, to edit friction, mesh or law.
///
/// Example: palpate calibrate --law mooney-rivlin --data uniaxial=u.csv --data biaxial=b.csv --json fit.json
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment, allow_negative_numbers = true)]
pub struct Args {
    /// Material law: neo-hookean, mooney-rivlin, reduced-polynomial:N (N = 1..6),
    /// yeoh (= reduced-polynomial:3), arruda-boyce, ogden:N, gent, veronda-westmann,
    /// humphrey.
    /// Not with --experiment, whose description names its laws; with
    /// --benchmark N1 or N3 it replaces the preset's law.
    #[arg(
        long,
        required_unless_present = "experiment",
        conflicts_with = "experiment"
    )]
    pub law: Option<String>,
    /// A lab's own experiment: an experiment file (TOML), a preset's name
    /// (palpate experiment list) or the description as JSON text. Its
    /// fitted parameters are estimated by finite elements from --data
    /// (displacement_mm, force_N), its fixed ones held.
    #[arg(long, value_name = "FILE|PRESET", conflicts_with_all = ["benchmark", "viscoelastic"])]
    pub experiment: Option<String>,
    /// Data to fit: TEST=FILE or TEST[key=value,...]=FILE for homogeneous
    /// tests (TEST = uniaxial, biaxial, planar, simple_shear; keys weight,
    /// axial_stretch, stress_unit, compression, skip_rows, or a column chosen
    /// by name such as force=Load); FILE or C1=FILE with --benchmark C1;
    /// FILE or force=FILE (a force record: displacement_mm, force_N) with
    /// --experiment or --benchmark N1. Repeat to fit jointly.
    #[arg(long = "data", required = true, value_name = "TEST=FILE")]
    pub data: Vec<String>,
    #[command(flatten)]
    pub reading: crate::cli::reading::ReadingArgs,
    /// The --data files are replicates of one material (implied by a FILE
    /// with wildcards, --data 'uniaxial=tests/EF10_0T_*.csv'): fitted pooled
    /// and one by one; the report gives each parameter's replicate mean and
    /// SD beside the pooled standard error, and batch A against batch B
    /// (Welch's t-test), the batches declared (--data 'uniaxial[batch=A]=...')
    /// or read from the file names (EF10_0T_A1 ... EF10_0T_B5).
    #[arg(long)]
    pub replicates: bool,
    /// Viscoelastic homogeneous tests (timed records, column time_s):
    /// qlv:N (quasi-linear viscoelasticity, N Prony terms on the nominal
    /// stress) or finite:N (uniaxial only: Prony terms on the isochoric second
    /// Piola stress, finite-strain). Adds g1,tau1_s,... to the law's parameters.
    #[arg(long, value_name = "FORM")]
    pub viscoelastic: Option<String>,
    /// Fit a benchmark's force record instead of homogeneous stress data: C1
    /// (analytic, lubricated compression), Q1 (the staged identification) or
    /// a preset of the experiment descriptions, N1 or N3 (finite elements,
    /// as --experiment N1; each evaluation is a full FE run).
    #[arg(long, value_name = "ID")]
    pub benchmark: Option<String>,
    /// Residual: absolute (default), relative ((f-y)/y; zero-stress points
    /// are left out) or normalised (each data set weighs equally).
    #[arg(long, default_value = "absolute")]
    pub residual: String,
    /// Estimator: lm (Levenberg-Marquardt, default), bfgs or lbfgs (argmin).
    /// `--method` is the same option.
    #[arg(long, visible_alias = "method", default_value = "lm")]
    pub estimator: String,
    /// Hold a parameter fixed, e.g. --fix C01=0 (MPa or dimensionless). Repeatable.
    #[arg(long = "fix", value_name = "NAME=VALUE")]
    pub fix: Vec<String>,
    /// Write the result as JSON: each parameter by name with value and
    /// standard error, R^2, RMS, iterations, evaluations, Drucker range.
    #[arg(long, value_name = "OUT.json")]
    pub json: Option<PathBuf>,
    /// Draw the data against the fit (SVG).
    #[arg(long, value_name = "OUT.svg")]
    pub plot: Option<PathBuf>,
    /// --benchmark Q1 (a ramp-and-hold record, columns time_s,displacement_mm,force_N):
    /// the stages of the inverse FE identification, `elastic,relaxation`
    /// (the law on the ramp with an elastic model, then the Prony terms with
    /// the law held), followed by a joint polish (docs/guide/two-stage.md).
    #[arg(long, value_name = "LIST")]
    pub stages: Option<String>,
    /// --benchmark Q1: Prony terms (default 2).
    #[arg(long, value_name = "N")]
    pub prony_terms: Option<usize>,
    /// --benchmark Q1: element size under the punch of the fits' mesh, mm (default 0.3).
    #[arg(long, value_name = "MM")]
    pub fit_mesh: Option<f64>,
    /// --benchmark Q1: correct each fit to a finer mesh with this element size under the punch, mm
    /// (off by default): the fit mesh's force is scaled, sample by sample, to this mesh's at an
    /// anchor, which the polish moves to its estimate round by round (output space mapping; a few
    /// runs on this mesh instead of every run). For deep records, where the fit mesh is stiff.
    #[arg(long, value_name = "MM")]
    pub correct_mesh: Option<f64>,
    /// --benchmark Q1: time step of the viscoelastic FE runs, s (default 1).
    #[arg(long, value_name = "S")]
    pub time_step: Option<f64>,
    /// --benchmark Q1: radius of the punch's rounded edge, mm (default 0.2; as palpate simulate --edge-radius).
    #[arg(long, value_name = "MM", allow_hyphen_values = true)]
    pub edge_radius: Option<f64>,
    /// --benchmark Q1 with --correct-mesh: radius of the edge of the fit mesh's punch, mm (default
    /// --edge-radius). The correcting mesh keeps the record's punch; an edge the fit mesh resolves
    /// (0.6 mm on the 0.3 mm mesh) keeps its force smooth in the parameters at depth, where the
    /// 0.2 mm edge makes it jump branch.
    #[arg(long, value_name = "MM", allow_hyphen_values = true)]
    pub fit_edge_radius: Option<f64>,
    /// --benchmark Q1: after the polish, refit it once corrected to a mesh with this element size
    /// under the punch, mm (off by default; level L of palpate simulate is 0.2/L): the report gives
    /// how far each estimate moves on that mesh, in its standard errors (the mesh's error in the
    /// estimates, which the standard errors do not hold). One run of that mesh.
    #[arg(long, value_name = "MM", allow_hyphen_values = true)]
    pub mesh_check: Option<f64>,
    /// --benchmark Q1: also fit every parameter at once from the default start (comparison).
    #[arg(long)]
    pub compare: bool,
    /// --benchmark Q1: profile-likelihood intervals of the polished parameters.
    #[arg(long)]
    pub profile: bool,
}

/// Runs `palpate calibrate`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if is_q1(&args) {
        let law = law_of(&args)?;
        return run_q1(&args, law);
    }
    // the options are checked (and the data read) by the fit first
    let result = fit(&args, &[])?;
    // How each file was read (metadata, columns, sign), when there is
    // anything to say beyond palpate's own format.
    let records = if experiment_of(&args)?.is_some() {
        read_experiment_data(&args, &[])?
    } else {
        read_data_opts(
            &args.data,
            args.benchmark.as_deref(),
            &[],
            &args.reading.defaults()?,
        )?
    };
    for d in &records {
        let about = d.describe();
        if !about.is_empty() {
            eprint!("{} ({} rows):\n{about}", d.file, d.observed.len());
        }
    }
    print!("{}", calibration_table(&result));
    if replicates_declared(&args) {
        anyhow::ensure!(
            args.experiment.is_none() && args.viscoelastic.is_none() && args.fix.is_empty(),
            "--replicates (or a --data FILE with wildcards): the replicate fits take a law's parameters, \
             not with --experiment, --viscoelastic or --fix"
        );
        let replicates = crate::steps::replicates::analyse(law_of(&args)?, &records, &result)?;
        print!("{}", replicates.table());
    }
    if let Some(p) = &args.json {
        write_json(p, &result)?;
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = &args.plot {
        write_atomic(p, fit_plot(&result).to_svg().as_bytes())?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}

/// Whether the `--data` files are replicates of one material: declared
/// with --replicates, or a FILE with wildcards.
fn replicates_declared(args: &Args) -> bool {
    args.replicates
        || args
            .data
            .iter()
            .any(|d| split_data(d).is_ok_and(|(_, _, p)| crate::records::replicates::is_pattern(p)))
}

/// The parsed `--law`.
fn law_of(args: &Args) -> anyhow::Result<Law> {
    super::parse_law(args.law.as_deref())
}

/// The experiment of `--experiment`, or of `--benchmark N1` (a preset of
/// the descriptions, its law replaced by `--law` when given); `None` for the
/// other calibrations ([`crate::api::experiment_spec`]).
pub fn experiment_of(args: &Args) -> anyhow::Result<Option<ExperimentSpec>> {
    crate::api::experiment_spec(
        args.experiment.as_deref(),
        args.benchmark.as_deref(),
        args.law.as_deref(),
    )
}

/// The options of the staged Q1 identification that were given.
fn q1_options_given(args: &Args) -> impl Iterator<Item = &'static str> {
    [
        (args.stages.is_some(), "--stages"),
        (args.prony_terms.is_some(), "--prony-terms"),
        (args.fit_mesh.is_some(), "--fit-mesh"),
        (args.correct_mesh.is_some(), "--correct-mesh"),
        (args.time_step.is_some(), "--time-step"),
        (args.edge_radius.is_some(), "--edge-radius"),
        (args.fit_edge_radius.is_some(), "--fit-edge-radius"),
        (args.mesh_check.is_some(), "--mesh-check"),
        (args.compare, "--compare"),
        (args.profile, "--profile"),
    ]
    .into_iter()
    .filter_map(|(given, name)| given.then_some(name))
}

/// `--fix NAME=VALUE` options as pairs; `example` completes the message
/// of one without `=`.
fn fixed_of(args: &Args, example: &str) -> anyhow::Result<Vec<(String, f64)>> {
    let mut fixed: Vec<(String, f64)> = Vec::new();
    for f in &args.fix {
        let (name, value) = split_pair(f, &format!("NAME=VALUE, e.g. {example}"))
            .map_err(|e| anyhow::anyhow!("--fix {e}"))?;
        let v: f64 = value
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| anyhow::anyhow!("--fix {f}: `{value}` is not a finite number"))?;
        anyhow::ensure!(
            !fixed.iter().any(|(n, _)| n == name),
            "--fix {f}: {name} is fixed twice; give each parameter once"
        );
        fixed.push((name.to_string(), v));
    }
    Ok(fixed)
}

/// `palpate calibrate --experiment`: the description's fitted parameters
/// from force records, its fixed ones (and `--fix`) held
/// ([`crate::api::calibrate_experiment`]).
fn fit_experiment(
    args: &Args,
    arrays: &[ArrayRecord],
    spec: ExperimentSpec,
) -> anyhow::Result<Calibration> {
    if let Some(name) = q1_options_given(args).next() {
        anyhow::bail!("{name}: not an option of an experiment's calibration (its description holds the model)");
    }
    anyhow::ensure!(
        args.viscoelastic.is_none(),
        "--viscoelastic: not an option of an experiment's calibration (its description holds the model)"
    );
    let options = crate::api::ExperimentFitOptions::parse(
        &args.residual,
        &args.estimator,
        fixed_of(args, "C10=0.002")?,
    )?;
    let data = read_experiment_data(args, arrays)?;
    let inputs: Vec<&Path> = data.iter().map(|d| Path::new(&d.file)).collect();
    let outputs = crate::run::output::given(&[("--json", &args.json), ("--plot", &args.plot)]);
    crate::run::output::check_outputs(&inputs, &outputs)?;
    crate::api::calibrate_experiment(spec, &data, &options)
}

/// The force records of an experiment's calibration
/// ([`read_force_records`] with the reading options of `--column`,
/// `--compression`, `--skip-rows`).
pub fn read_experiment_data(args: &Args, arrays: &[ArrayRecord]) -> anyhow::Result<Vec<TestData>> {
    read_force_records(&args.data, arrays, &args.reading.defaults()?)
}

/// Whether `--benchmark Q1` (the staged identification, files only).
pub fn is_q1(args: &Args) -> bool {
    args.benchmark
        .as_deref()
        .is_some_and(|b| b.eq_ignore_ascii_case("q1"))
}

/// The fit of `palpate calibrate` (not Q1) without its outputs: what
/// [`run`] prints and writes, for callers that hold the data in memory
/// (`--data TEST=<array:K>` takes `arrays[K]`, [`crate::records::arrays`]):
/// the options read, then [`crate::api::calibrate`].
pub fn fit(args: &Args, arrays: &[ArrayRecord]) -> anyhow::Result<Calibration> {
    if let Some(spec) = experiment_of(args)? {
        return fit_experiment(args, arrays, spec);
    }
    let law = args
        .law
        .as_deref()
        .ok_or_else(|| anyhow::anyhow!("--law: give the material law (e.g. --law neo-hookean)"))?;
    law.parse::<Law>()
        .map_err(|e| anyhow::anyhow!("--law {law}: {e}"))?;
    anyhow::ensure!(
        !is_q1(args),
        "--benchmark Q1: the staged identification reads its record from a file (palpate calibrate --benchmark Q1 --data FILE)"
    );
    if let Some(name) = q1_options_given(args).next() {
        anyhow::bail!("{name}: an option of --benchmark Q1 (the staged inverse FE identification)");
    }
    let options = crate::api::CalibrateOptions::parse(
        law,
        &args.residual,
        &args.estimator,
        fixed_of(args, "C01=0")?,
        args.viscoelastic.as_deref(),
    )?;
    let data = read_data_opts(
        &args.data,
        args.benchmark.as_deref(),
        arrays,
        &args.reading.defaults()?,
    )?;
    let inputs: Vec<&Path> = data.iter().map(|d| Path::new(&d.file)).collect();
    let outputs = crate::run::output::given(&[("--json", &args.json), ("--plot", &args.plot)]);
    crate::run::output::check_outputs(&inputs, &outputs)?;
    crate::api::calibrate(&data, &options)
}

/// `palpate calibrate --benchmark Q1`: the staged inverse FE identification
/// ([`crate::apps::two_stage`]).
fn run_q1(args: &Args, law: Law) -> anyhow::Result<()> {
    use crate::apps::two_stage::{identify, report, Q1Record};
    anyhow::ensure!(
        args.data.len() == 1,
        "--benchmark Q1: give one record (--data FILE), got {}",
        args.data.len()
    );
    for (given, name) in [
        (args.viscoelastic.is_some(), "--viscoelastic"),
        (!args.fix.is_empty(), "--fix"),
        (args.plot.is_some(), "--plot"),
    ] {
        anyhow::ensure!(!given, "{name}: not an option of --benchmark Q1");
    }
    anyhow::ensure!(
        args.residual == "absolute" && args.estimator == "lm",
        "--benchmark Q1 fits by Levenberg-Marquardt on absolute residuals (--residual absolute, --estimator lm)"
    );
    let o = crate::api::identify::Q1Options {
        stages: args.stages.clone(),
        prony_terms: args.prony_terms,
        fit_mesh: args.fit_mesh,
        correct_mesh: args.correct_mesh,
        time_step: args.time_step,
        edge_radius: args.edge_radius,
        fit_edge_radius: args.fit_edge_radius,
        mesh_check: args.mesh_check,
        compare: args.compare,
        profile: args.profile,
    }
    .two_stage(law)?;
    let path = args.data[0]
        .split_once('=')
        .filter(|(t, _)| t.eq_ignore_ascii_case("q1"))
        .map_or(args.data[0].as_str(), |(_, p)| p);
    let outputs = crate::run::output::given(&[("--json", &args.json)]);
    crate::run::output::check_outputs(&[Path::new(path)], &outputs)?;
    let record = Q1Record::read(Path::new(path))?;
    let say = |s: &str| eprintln!("{s}");
    let result = identify(&record, &o, &say)?;
    print!("{}", report(&result, None));
    if let Some(p) = &args.json {
        write_json(p, &result)?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}
