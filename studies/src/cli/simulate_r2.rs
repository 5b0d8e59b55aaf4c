//! `palpate simulate --benchmark R2`: the scan ([`crate::api::simulate::r2::scan`])
//! written as the options ask: the rolled pass to `OUT.csv`
//! (`position_mm,force_N,force_x_N`), the pressing phase to `OUT.press.csv`,
//! a `.vtu` and a plot.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, Context};

use super::simulate::Args;
use crate::api::simulate::r2::{pass_text, press_text, scan, Scan, ScanNotConverged, Scanned};
use crate::api::simulate::SimulateOptions;
use crate::report::plot::{Plot, Series};
use crate::run::output::write_atomic;

/// Where the pressing phase goes: `OUT.csv` -> `OUT.press.csv`.
fn press_path(csv: &Path) -> PathBuf {
    let stem = csv
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "r2".into());
    csv.with_file_name(format!("{stem}.press.csv"))
}

/// Runs the R2 benchmark with the options read from `args`.
pub fn run(args: &Args, options: &SimulateOptions) -> anyhow::Result<()> {
    let press_csv = args.csv.as_deref().map(press_path);
    crate::run::output::check_outputs(
        &[],
        &crate::run::output::given(&[
            ("--csv", &args.csv),
            ("--csv (pressing phase)", &press_csv),
            ("--vtu", &args.vtu),
            ("--plot", &args.plot),
        ]),
    )?;
    let Scanned { scan: s, system } = match scan(options, &crate::api::Stderr) {
        Ok(s) => s,
        Err(e) => {
            if let Some(stop) = e.downcast_ref::<ScanNotConverged>() {
                let p = &stop.partial;
                if let Some(path) = &press_csv {
                    write_press(path, p)?;
                }
                if let Some(path) = &args.csv {
                    write_atomic(
                        path,
                        pass_text(&p.comments, &p.position_mm, &p.force_n, &p.force_x_n, None)
                            .as_bytes(),
                    )?;
                    eprintln!(
                        "wrote the {} converged positions to {}",
                        p.position_mm.len(),
                        path.display()
                    );
                }
            }
            return Err(e);
        }
    };
    if let Some(path) = &press_csv {
        write_press(path, &s)?;
    }
    let text = pass_text(
        &s.comments,
        &s.position_mm,
        &s.force_n,
        &s.force_x_n,
        s.error_estimate_n.as_deref(),
    );
    if let Some(path) = &args.csv {
        write_atomic(path, text.as_bytes())?;
    }
    if let (Some(path), Some(sys)) = (&args.vtu, &system) {
        let vtu = palpate_fe::vtu::to_vtu(sys).map_err(|e| anyhow!("{e}"))?;
        write_atomic(path, vtu.as_bytes())?;
    }
    if let Some(path) = &args.plot {
        let mut plot = Plot::new(&s.title, "wheel position x (mm)", "force (N)")
            .with(Series::line("vertical force", &s.position_mm, &s.force_n))
            .with(Series::dashed(
                "horizontal force",
                &s.position_mm,
                &s.force_x_n,
            ));
        if !s.nodules_x.is_empty() {
            let ys = vec![0.0; s.nodules_x.len()];
            plot = plot.with(Series::markers("nodules (x)", &s.nodules_x, &ys));
        }
        write_atomic(path, plot.to_svg().as_bytes())
            .with_context(|| format!("plot {}", path.display()))?;
    }
    if args.csv.is_none() {
        print!("{text}");
    }
    Ok(())
}

fn write_press(path: &Path, s: &Scan) -> anyhow::Result<()> {
    let text = press_text(
        &s.press_comments,
        s.press_x,
        &s.press_depth_mm,
        &s.press_force_n,
        &s.press_force_x_n,
    );
    write_atomic(path, text.as_bytes())
}
