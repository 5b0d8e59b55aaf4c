//! Testing-machine files read as they come: the phantom compression tests
//! of Dawood et al. (2026, CC BY 4.0; `data/real/phantom_dawood2026/README.md`)
//! with their metadata lines, column names with units and sign
//! conventions, and copies of them written as other machines write files
//! (compression positive, tabs, semicolons with decimal commas, trailing
//! separators, a byte-order mark, no metadata, stresses in MPa).

use palpate_analytic::Mode;
use palpate_studies::records::{ReadOptions, TestData, TestKind};
use std::path::{Path, PathBuf};
use std::process::Command;

/// A file of the database (`EF10_0T_A1.csv` is in its folder `EF10_0T`);
/// `""`: the folder of EF10_0T.
fn phantom(name: &str) -> PathBuf {
    let folder = name.rsplit_once('_').map_or("EF10_0T", |(f, _)| f);
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data/real/phantom_dawood2026")
        .join(folder)
        .join(name)
}

const A1: &str = "EF10_0T_A1.csv";
const UNIAXIAL: TestKind = TestKind::Homogeneous(Mode::Uniaxial);

fn read(path: &Path, options: &[(&str, &str)]) -> anyhow::Result<TestData> {
    let mut o = ReadOptions::default();
    for (k, v) in options {
        o.set(k, v)?;
    }
    TestData::read_with("uniaxial", UNIAXIAL, path, o)
}

fn err(path: &Path, options: &[(&str, &str)]) -> String {
    format!("{:#}", read(path, options).unwrap_err())
}

/// A scratch directory of this test binary.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("palpate-records-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The phantom file with each data row's fields passed through `row` (the
/// fields as strings; metadata and header lines through `other`), joined by `sep`.
fn rewrite(
    name: &str,
    out: &str,
    other: impl Fn(usize, &str) -> Option<String>,
    row: impl Fn(Vec<f64>) -> Vec<String>,
    sep: &str,
) -> PathBuf {
    let text = std::fs::read_to_string(phantom(A1)).unwrap();
    let mut s = String::new();
    for (i, line) in text.lines().enumerate() {
        let fields: Option<Vec<f64>> = line.split(',').map(|f| f.parse().ok()).collect();
        match fields {
            Some(v) if v.len() == 7 => {
                s.push_str(&row(v).join(sep));
                s.push('\n');
            }
            _ => {
                if let Some(l) = other(i + 1, line) {
                    s.push_str(&l);
                    s.push('\n');
                }
            }
        }
    }
    let p = scratch(name).join(out);
    std::fs::write(&p, s).unwrap();
    p
}

fn as_is(v: Vec<f64>) -> Vec<String> {
    v.iter().map(|x| x.to_string()).collect()
}

/// Columns: 0 time, 1 compression, 2 load, 3 strain, 4 stress kPa, 5 true strain, 6 true stress kPa.
fn negate(cols: &'static [usize]) -> impl Fn(Vec<f64>) -> Vec<String> {
    move |v| {
        v.iter()
            .enumerate()
            .map(|(k, x)| if cols.contains(&k) { -x } else { *x }.to_string())
            .collect()
    }
}

#[test]
fn the_phantom_file_loads_with_its_metadata_sign_and_units() {
    let d = read(&phantom(A1), &[]).unwrap();
    assert_eq!(d.observed.len(), 1202);
    let stretch = &d.loading.drive;
    // Last row: Engineering Strain -0.666668, Engineering Stress -254.303192 kPa.
    assert!(
        (stretch[1201] - (1.0 - 0.666668)).abs() < 1e-12,
        "{}",
        stretch[1201]
    );
    assert!(
        (d.observed[1201] + 0.254303192).abs() < 1e-12,
        "{}",
        d.observed[1201]
    );
    assert_eq!(d.sign, "compression, written negative as palpate's");
    let s = d.specimen().unwrap().unwrap();
    assert_eq!((s.diameter_mm, s.height_mm), (Some(50.0), Some(30.0)));
    assert_eq!(s.radius_mm(), Some(25.0));
    assert_eq!(d.metadata.get("machine"), Some("INSTRON 5900"));
    assert_eq!(d.metadata.get("speed"), Some("10"));
    assert_eq!(d.metadata.entries[0].key, "EF10_0T_A_sample_1");
    let about = d.describe();
    for says in [
        "Cylinder Diameter: 50mm",
        "Load cell: 1kN",
        "Engineering Stress (kPa) -> stress_kPa",
        "sign: compression",
    ] {
        assert!(about.contains(says), "{about}");
    }
    // As a force record: compression and load are positive, as palpate takes them.
    let f =
        TestData::read_with("record", TestKind::C1, &phantom(A1), ReadOptions::default()).unwrap();
    assert!((f.observed[1201] - 499.32315).abs() < 1e-9);
    assert!((f.loading.drive[1201] - 20.00004).abs() < 1e-9);
    assert_eq!(f.sign, "compression, written positive as palpate's");
    // The other phantom (10 kN load cell) too.
    let b3 = read(&phantom("EF30_50T_B3.csv"), &[]).unwrap();
    assert!((b3.observed.last().unwrap() + 0.128142159).abs() < 1e-12);
}

/// A neo-Hookean tension record (mu = 10 kPa) to 67 % strain, with `head`
/// (metadata lines) before its header: a curve that softens as it stretches.
fn neo_hookean_tension(name: &str, head: &str) -> PathBuf {
    let mut s = format!("{head}Engineering Strain [-],Engineering Stress (kPa)\n");
    for i in 0..=100 {
        let e = 0.0067 * i as f64;
        let l = 1.0 + e;
        s.push_str(&format!("{e},{}\n", 10.0 * (l - 1.0 / (l * l))));
    }
    let p = scratch("tension").join(name);
    std::fs::write(&p, s).unwrap();
    p
}

#[test]
fn compression_written_positive_is_recognised_from_the_file_and_its_curve() {
    let original = read(&phantom(A1), &[]).unwrap();
    // Strains and stresses positive in compression (the force columns as they are).
    let positive = rewrite(
        "positive",
        "positive.csv",
        |_, l| Some(l.to_string()),
        negate(&[3, 4, 5, 6]),
        ",",
    );
    // The file says `Compression test` and the curve stiffens as compression
    // does: read as compression, to the same numbers, and the report says why.
    let d = read(&positive, &[]).unwrap();
    assert_eq!(d.observed, original.observed);
    assert_eq!(d.loading.drive, original.loading.drive);
    for says in [
        "compression, written positive in the file (line 2 says `Compression test`;",
        "the curve stiffens as a compression does: area ratio 0.",
        "to strain 0.667",
        "converted",
    ] {
        assert!(d.sign.contains(says), "{}", d.sign);
    }
    assert!(d.describe().contains("sign: compression, written positive"));
    // Declared a compression test, whichever sign: the same.
    for file in [&positive, &phantom(A1)] {
        let d = read(file, &[("compression", "yes")]).unwrap();
        assert_eq!(d.observed, original.observed);
    }
    // A curve that softens as tension does, in a file that says compression:
    // ambiguous, refused naming the options.
    let soft = neo_hookean_tension("says_compression.csv", "Compression test\n");
    let e = err(&soft, &[]);
    for says in [
        "says_compression.csv:",
        "ambiguous",
        "line 1 says `Compression test`",
        "the curve area ratio 1.1",
        "compression=positive",
        "--compression positive",
        "compression=none",
    ] {
        assert!(e.contains(says), "{e}");
    }
    // Tension declared as compression: refused, saying why.
    let tension = neo_hookean_tension("tension.csv", "");
    assert_eq!(read(&tension, &[]).unwrap().sign, "tension");
    for declared in ["positive", "yes"] {
        let e = err(&tension, &[("compression", declared)]);
        for says in [
            "tension.csv:102:",
            &format!("declared a compression test written positive (compression={declared})"),
            "its curve softens as the strain grows (area ratio 1.1",
            "as a tension test does",
            "set compression=none",
        ] {
            assert!(e.contains(says), "{e}");
        }
    }
    // A strain of 1 or more is tension whatever the convention.
    let far = scratch("tension").join("far.csv");
    std::fs::write(&far, "strain,stress_MPa\n0,0\n0.5,0.2\n1.5,0.5\n").unwrap();
    let e = err(&far, &[("compression", "yes")]);
    assert!(
        e.contains("far.csv:4: `strain` is 1.5 but the record is declared a compression test (compression=yes)"),
        "{e}"
    );
    let stretch = scratch("tension").join("stretch.csv");
    std::fs::write(&stretch, "stretch,stress_MPa\n1,0\n1.2,0.2\n").unwrap();
    let e = err(&stretch, &[("compression", "yes")]);
    assert!(
        e.contains(
            "stretch.csv:3: declared a compression test (compression=yes), but `stretch` is 1.2"
        ),
        "{e}"
    );
    let d = read(&positive, &[("compression", "positive")]).unwrap();
    assert_eq!(d.observed, original.observed);
    assert_eq!(d.loading.drive, original.loading.drive);
    assert_eq!(
        d.sign,
        "compression, written positive in the file, converted"
    );
    // The sign contradicts what is declared: refused.
    let e = err(&positive, &[("compression", "negative")]);
    assert!(
        e.contains("compression=negative, but `strain` is")
            && e.contains("set compression=positive"),
        "{e}"
    );
    let e = err(&phantom(A1), &[("compression", "positive")]);
    assert!(
        e.contains("compression=positive, but `strain` is -0.666668"),
        "{e}"
    );
    let e = err(&phantom(A1), &[("compression", "none")]);
    assert!(
        e.contains("compression=none (a tension test), but `strain` is -0.666668"),
        "{e}"
    );
    // A tension test (no word of compression) reads as tension; declared as
    // compression it is refused.
    let tension = rewrite(
        "tension",
        "tension.csv",
        |i, l| (i >= 8).then(|| l.replace("Compression (mm)", "Extension (mm)")),
        negate(&[3, 4, 5, 6]),
        ",",
    );
    // (Negated, the true pair is no longer a true pair: the engineering pair is read.)
    let eng = [
        ("strain", "Engineering Strain"),
        ("stress", "Engineering Stress"),
    ];
    let t = read(&tension, &eng).unwrap();
    assert_eq!(t.sign, "tension");
    assert!(t.observed[1201] > 0.25);
    let e = err(&tension, &[eng[0], eng[1], ("compression", "negative")]);
    assert!(
        e.contains("tension.csv:") && e.contains("compression=negative, but"),
        "{e}"
    );
    // A force record written negative in compression.
    let neg = rewrite(
        "force",
        "force.csv",
        |_, l| Some(l.to_string()),
        negate(&[1, 2]),
        ",",
    );
    let c1 = |o: ReadOptions| TestData::read_with("record", TestKind::C1, &neg, o);
    let e = format!("{:#}", c1(ReadOptions::default()).unwrap_err());
    assert!(
        e.contains("`displacement_mm` is -20.00004") && e.contains("compression=negative"),
        "{e}"
    );
    let mut o = ReadOptions::default();
    o.set("compression", "negative").unwrap();
    let f = c1(o).unwrap();
    assert!((f.observed[1201] - 499.32315).abs() < 1e-9);
}

#[test]
fn tabs_semicolons_trailing_separators_bom_and_no_metadata_read_the_same() {
    let original = read(&phantom(A1), &[]).unwrap();
    let drop_meta = |i: usize, l: &str| (i >= 8).then(|| l.to_string());
    let keep = |_: usize, l: &str| Some(l.to_string());
    let decimal_comma = |v: Vec<f64>| -> Vec<String> {
        v.iter().map(|x| x.to_string().replace('.', ",")).collect()
    };
    let files = [
        rewrite(
            "sep",
            "tab.csv",
            |_, l| Some(l.replace(',', "\t")),
            as_is,
            "\t",
        ),
        rewrite(
            "sep",
            "semicolon.csv",
            |_, l| Some(l.replace(',', ";")),
            decimal_comma,
            ";",
        ),
        rewrite(
            "sep",
            "trailing.csv",
            |_, l| Some(format!("{l},")),
            |v| {
                let mut f = as_is(v);
                f.push(String::new());
                f
            },
            ",",
        ),
        rewrite("sep", "no_metadata.csv", drop_meta, as_is, ","),
        rewrite(
            "sep",
            "bom.csv",
            |i, l| {
                Some(if i == 1 {
                    format!("\u{feff}{l}")
                } else {
                    l.to_string()
                })
            },
            as_is,
            ",",
        ),
        rewrite("sep", "crlf.csv", |_, l| Some(format!("{l}\r")), as_is, ","),
        // Stresses given in MPa.
        rewrite(
            "sep",
            "mpa.csv",
            |_, l| Some(l.replace("(kPa)", "(MPa)")),
            |v| {
                v.iter()
                    .enumerate()
                    .map(|(k, x)| if k == 4 || k == 6 { x / 1000.0 } else { *x }.to_string())
                    .collect()
            },
            ",",
        ),
        rewrite("sep", "same.csv", keep, as_is, ","),
    ];
    for f in &files {
        let d = read(f, &[]).unwrap_or_else(|e| panic!("{}: {e:#}", f.display()));
        assert_eq!(d.loading.drive.len(), 1202, "{}", f.display());
        for (a, b) in d.observed.iter().zip(&original.observed) {
            assert!(
                (a - b).abs() <= 1e-15 * b.abs().max(1e-3),
                "{}: {a} {b}",
                f.display()
            );
        }
        assert_eq!(d.loading.drive, original.loading.drive, "{}", f.display());
    }
    // One stress column relabelled MPa without its values changed: refused,
    // naming the column.
    let half = rewrite(
        "sep",
        "half_mpa.csv",
        |_, l| Some(l.replace("Engineering Stress (kPa)", "Engineering Stress (MPa)")),
        as_is,
        ",",
    );
    let e = err(&half, &[]);
    assert!(
        e.contains("half_mpa.csv:")
            && e.contains("column `true_stress_kPa`")
            && e.contains("disagree"),
        "{e}"
    );
}

#[test]
fn columns_chosen_by_name_and_rows_to_skip() {
    let original = read(&phantom(A1), &[]).unwrap();
    // The true pair alone, converted to the nominal stress of the stretch it gives.
    let t = read(
        &phantom(A1),
        &[
            ("true_strain", "True Strain"),
            ("true_stress", "True Stress (kPa)"),
        ],
    )
    .unwrap();
    for (a, b) in t.observed.iter().zip(&original.observed).skip(100) {
        assert!((a - b).abs() < 1e-3 * b.abs() + 1e-7, "{a} {b}");
    }
    let e = err(&phantom(A1), &[("stress", "Stress")]);
    assert!(
        e.contains("stress=Stress: no column `Stress` (header has: Time (s), Compression (mm)"),
        "{e}"
    );
    let e = read(&phantom(A1), &[("force", "Load"), ("force", "Time")]).unwrap_err();
    assert!(
        format!("{e:#}").contains("the force column is already chosen (force=Load)"),
        "{e:#}"
    );
    let d = read(&phantom(A1), &[("skip_rows", "7")]).unwrap();
    assert_eq!(d.metadata.entries.len(), 7);
    let e = err(&phantom(A1), &[("skip_rows", "3")]);
    assert!(
        e.contains("EF10_0T_A1.csv:4: `Cylinder Height: 30mm;`"),
        "{e}"
    );
}

fn palpate(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_palpate"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn calibrate_reads_the_phantom_file_and_its_positive_copy_to_the_same_fit() {
    let file = phantom(A1);
    let data = format!("uniaxial={}", file.display());
    let out = palpate(&["calibrate", "--law", "neo-hookean", "--data", &data]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("Cylinder Height: 30mm") && stderr.contains("sign: compression"),
        "{stderr}"
    );
    let original = String::from_utf8_lossy(&out.stdout).to_string();
    let positive = rewrite(
        "cli",
        "positive.csv",
        |_, l| Some(l.to_string()),
        negate(&[3, 4, 5, 6]),
        ",",
    );
    let data = format!("uniaxial={}", positive.display());
    // Recognised from the file and its curve, and said so; declared, the same.
    let out = palpate(&["calibrate", "--law", "neo-hookean", "--data", &data]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains(
            "sign: compression, written positive in the file (line 2 says `Compression test`;"
        ),
        "{stderr}"
    );
    assert_eq!(String::from_utf8_lossy(&out.stdout), original);
    for sign in ["positive", "yes"] {
        let out = palpate(&[
            "calibrate",
            "--law",
            "neo-hookean",
            "--data",
            &data,
            "--compression",
            sign,
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(String::from_utf8_lossy(&out.stdout), original);
    }
    // A tension record declared as compression is refused.
    let tension = neo_hookean_tension("cli.csv", "");
    let out = palpate(&[
        "calibrate",
        "--law",
        "neo-hookean",
        "--data",
        &format!("uniaxial={}", tension.display()),
        "--compression",
        "yes",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("as a tension test does"),
        "{stderr}"
    );
    // Columns chosen on the command line, overridden in brackets.
    let out = palpate(&[
        "calibrate",
        "--law",
        "neo-hookean",
        "--column",
        "stress=Nothing",
        "--data",
        &format!("uniaxial[stress=Engineering Stress]={}", file.display()),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = palpate(&[
        "calibrate",
        "--law",
        "neo-hookean",
        "--column",
        "load=Load",
        "--data",
        &data,
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("--column load=Load: unknown role `load`"),
        "{stderr}"
    );
}

#[test]
fn a_manifest_data_table_states_the_same_options() {
    let original = read(&phantom(A1), &[]).unwrap();
    let positive = rewrite(
        "manifest",
        "positive.csv",
        |_, l| Some(l.to_string()),
        negate(&[3, 4, 5, 6]),
        ",",
    );
    let spec: palpate_studies::records::DataSpec = toml::from_str(
        r#"file = "positive.csv"
test = "uniaxial"
compression = "positive"
columns = { strain = "Engineering Strain", stress = "Engineering Stress" }
skip_rows = 7
"#,
    )
    .unwrap();
    let o = spec.read_options().unwrap();
    assert_eq!(o.columns.len(), 2);
    let d = TestData::read_with("phantom", UNIAXIAL, &positive, o).unwrap();
    assert_eq!(d.observed, original.observed);
    assert_eq!(d.columns_read.len(), 5, "{:?}", d.columns_read);
    let bad: palpate_studies::records::DataSpec =
        toml::from_str("file = \"x.csv\"\ntest = \"uniaxial\"\ncolumns = { load = \"Load\" }\n")
            .unwrap();
    let e = format!("{:#}", bad.read_options().unwrap_err());
    assert!(
        e.contains("columns.load: unknown column role; expected one of time, displacement, force"),
        "{e}"
    );
    let bad: palpate_studies::records::DataSpec =
        toml::from_str("file = \"x.csv\"\ntest = \"uniaxial\"\ncompression = \"up\"\n").unwrap();
    let e = format!("{:#}", bad.read_options().unwrap_err());
    assert!(e.contains("compression `up`: expected negative"), "{e}");
}

/// Ecoflex 00-10 without thinner, casts A and B, three tests each
/// (`EF10_0T_{A,B}{1,2,3}.csv`). Reference values: each file's neo-Hookean
/// C10 by linear least squares on its 1202 rows (P = 2 C10 (l - l^-2)),
/// and `scipy.stats.ttest_ind(B, A, equal_var=False)` (scipy 1.x).
const C10: [(&str, f64); 6] = [
    ("EF10_0T_A1", 0.011061784672224757),
    ("EF10_0T_A2", 0.011112203856170054),
    ("EF10_0T_A3", 0.01113580228635267),
    ("EF10_0T_B1", 0.010828449926298984),
    ("EF10_0T_B2", 0.010943450795859637),
    ("EF10_0T_B3", 0.010564889866369243),
];

#[test]
fn replicates_are_fitted_pooled_and_one_by_one_with_the_batch_test() {
    use palpate_studies::model::calibration::{calibrate, Request};
    let records: Vec<TestData> = C10
        .iter()
        .map(|(f, _)| read(&phantom(&format!("{f}.csv")), &[]).unwrap())
        .collect();
    let law: palpate_material::Law = "neo-hookean".parse().unwrap();
    let pooled = calibrate(Request {
        law,
        model: None,
        fitted: &records,
        predict: &[],
        residual: palpate_inverse::ResidualKind::Absolute,
        method: palpate_inverse::Method::LevenbergMarquardt(Default::default()),
        fixed: Vec::new(),
        observer: None,
        viscous: None,
    })
    .unwrap();
    let r = palpate_studies::steps::replicates::analyse(law, &records, &pooled).unwrap();
    let close = |a: f64, b: f64, tol: f64| (a - b).abs() <= tol * b.abs();
    for (fit, (name, c10)) in r.fits.iter().zip(C10) {
        assert_eq!(fit.record, name);
        assert_eq!(fit.batch.as_deref(), Some(&name[8..9]));
        assert!(close(fit.values[0], c10, 1e-6), "{name}: {}", fit.values[0]);
    }
    assert!(
        close(r.mean[0], 0.010941096900545892, 1e-6),
        "{}",
        r.mean[0]
    );
    assert!(close(r.sd[0], 0.00021724637163923673, 1e-4), "{}", r.sd[0]);
    assert!(
        close(r.pooled[0], 0.01094015969123547, 1e-6),
        "{}",
        r.pooled[0]
    );
    // The pooled standard error is ten times smaller than the spread of
    // the specimens.
    let se = r.pooled_se[0].unwrap();
    assert!(r.sd[0] / se > 5.0, "SD {} SE {se}", r.sd[0]);
    let b = r.batches.as_ref().unwrap();
    assert_eq!((b.a.as_str(), b.b.as_str(), b.n_a, b.n_b), ("A", "B", 3, 3));
    assert_eq!(b.source, "file names");
    let w = b.tests[0].unwrap();
    assert!(close(w.t, -2.841103217821117, 1e-4), "{}", w.t);
    assert!(close(w.df, 2.1515990107941065, 1e-4), "{}", w.df);
    assert!(close(w.p, 0.09644479955522474, 1e-4), "{}", w.p);

    // The CLI: a file pattern declares replicates (the phantom's ten
    // tests); the table says the same as the library on them.
    let pattern = phantom("EF10_0T_*.csv");
    let out = palpate(&[
        "calibrate",
        "--law",
        "neo-hookean",
        "--data",
        &format!("uniaxial={}", pattern.display()),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for says in [
        "replicates: 10 records, neo-hookean fitted pooled and one by one",
        "EF10_0T_B5",
        "0.01056",
        "rep. mean",
        "0.01101",
        "2.056e-4",
        "batch A (5 records) against batch B (5 records), batches from the file names",
        "-3.245",
        "1.808e-2",
    ] {
        assert!(stdout.contains(says), "{says}:\n{stdout}");
    }
    // Declared batches override the names; a file without one is refused.
    let dir = phantom("");
    let out = palpate(&[
        "calibrate",
        "--law",
        "neo-hookean",
        "--data",
        &format!(
            "uniaxial[batch=early]={}",
            dir.join("EF10_0T_?1.csv").display()
        ),
        "--data",
        &format!(
            "uniaxial[batch=late]={}",
            dir.join("EF10_0T_?2.csv").display()
        ),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(
            "batch early (2 records) against batch late (2 records), batches from the declared"
        ),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = palpate(&[
        "calibrate",
        "--law",
        "neo-hookean",
        "--replicates",
        "--data",
        &format!("uniaxial[batch=A]={}", dir.join("EF10_0T_A1.csv").display()),
        "--data",
        &format!("uniaxial={}", dir.join("EF10_0T_B1.csv").display()),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("EF10_0T_B1.csv has no batch while others do"),
        "{stderr}"
    );
    let out = palpate(&[
        "calibrate",
        "--law",
        "neo-hookean",
        "--data",
        &format!("uniaxial={}", dir.join("EF99_*.csv").display()),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success()
            && stderr.contains("no file of")
            && stderr.contains("matches `EF99_*.csv`"),
        "{stderr}"
    );
}

/// The AR(1) posterior of a full, dense phantom record (1202 smooth rows,
/// whose second differences put the noise at 1e-5 MPa while the
/// neo-Hookean misfit is 1e-2 MPa): the residuals are a smooth curve, the
/// correlation of successive ones within 1e-4 of 1. The Laplace start of
/// the chains used to fail there; the chains converge (R-hat < 1.01).
/// About 9 s of CPU.
#[test]
fn sample_ar1_on_a_full_phantom_record_converges() {
    let json = scratch("ar1").join("post.json");
    let out = palpate(&[
        "sample",
        "--law",
        "neo-hookean",
        "--ar1",
        "--data",
        &format!("uniaxial={}", phantom(A1).display()),
        "--json",
        json.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let c = &v["convergence"];
    assert_eq!(c["converged"], true, "{v}");
    assert!(c["rhat_max"].as_f64().unwrap() < 1.01, "{c}");
    assert!(
        stdout.contains("between-sample correlation of `uniaxial` (AR(1) phi): 1 - "),
        "{stdout}"
    );
    assert!(
        stdout.contains("innovation SD sigma sqrt(1 - phi^2)"),
        "{stdout}"
    );
    let phi = v["params"]["phi"]["mean"]
        .as_f64()
        .unwrap_or_else(|| panic!("{v}"));
    assert!(phi > 0.9999 && phi < 1.0, "{phi}");
}
