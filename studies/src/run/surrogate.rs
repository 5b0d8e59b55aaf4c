//! The on-disk cache of surrogates (`palpate_uq::surrogate`), shared by
//! `palpate sample --benchmark N1|N3|Q1` and `palpate localize`.
//!
//! A surrogate is stored as `<cache>/surrogate-<key>.json`, where the key is
//! the SHA-256 of everything that defines it
//! ([`palpate_uq::surrogate::SurrogateRequest::key`]): the caller's
//! description of the model (its spec: kind, law, mesh, friction, ...), the
//! code version ([`code_version`]), the model's name and outputs, the
//! loading history, the box and the design sizes. A second run with the same
//! inputs loads it instead of running the model again; any change misses and
//! builds afresh. Files are written atomically (`output::write_atomic`), so
//! an interrupted build never leaves a truncated entry; an unreadable entry
//! is reported and rebuilt.

use crate::run::limits::Progress;
use crate::run::output::write_atomic;
use palpate_core::{ForwardModel, Loading};
use palpate_uq::surrogate::{ParamBox, Surrogate, SurrogateOptions, SurrogateRequest};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Whether a surrogate came from the cache or was built now, and its file.
#[derive(Debug, Clone, PartialEq)]
pub enum CacheStatus {
    /// Loaded from this file.
    Hit(PathBuf),
    /// Built and stored in this file.
    Built(PathBuf),
}

impl CacheStatus {
    /// The cache file.
    pub fn path(&self) -> &Path {
        match self {
            CacheStatus::Hit(p) | CacheStatus::Built(p) => p,
        }
    }

    /// `hit` or `built`.
    pub fn word(&self) -> &'static str {
        match self {
            CacheStatus::Hit(_) => "hit",
            CacheStatus::Built(_) => "built",
        }
    }
}

/// The default cache folder: `$PALPATE_CACHE`, else
/// `$XDG_CACHE_HOME/palpate/surrogates`, else `$HOME/.cache/palpate/surrogates`,
/// else `.palpate-cache/surrogates` in the working directory.
pub fn default_cache_dir() -> PathBuf {
    if let Some(p) = setting("PALPATE_CACHE") {
        return PathBuf::from(p);
    }
    user_cache()
        .map(|base| base.join("surrogates"))
        .unwrap_or_else(|| PathBuf::from(".palpate-cache/surrogates"))
}

/// A user setting of the caches: the variable `k`, when set and not empty.
fn setting(k: &str) -> Option<std::ffi::OsString> {
    std::env::var_os(k).filter(|v| !v.is_empty())
}

/// The user's palpate cache folder: `$XDG_CACHE_HOME/palpate`, else
/// `$HOME/.cache/palpate`.
fn user_cache() -> Option<PathBuf> {
    let base = setting("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| setting("HOME").map(|h| PathBuf::from(h).join(".cache")))?;
    Some(base.join("palpate"))
}

/// The cache folder of the meshes chosen for an accuracy (`simulate
/// --accuracy`): `$XDG_CACHE_HOME/palpate`, else `$HOME/.cache/palpate`;
/// `None` without either (no cache). The user settings of the caches are
/// read here, in one place.
pub fn mesh_cache_dir() -> Option<PathBuf> {
    user_cache()
}

/// The code version in a cache key: the palpate version and the SHA-256 of
/// the running executable, so that any rebuild of the code (a changed
/// element, solver tolerance or mesh generator) invalidates the cache rather
/// than reusing answers of other code. Computed once per process.
///
/// `$PALPATE_CODE_VERSION`, when set, replaces the executable's hash: the
/// user vouches that the finite-element code is the same, so that binaries
/// of one commit (the `palpate` CLI and a release bench/example) share the
/// surrogates in a cache instead of each training its own.
pub fn code_version() -> &'static str {
    static V: OnceLock<String> = OnceLock::new();
    V.get_or_init(|| {
        if let Some(v) = setting("PALPATE_CODE_VERSION") {
            return format!(
                "palpate {} code {}",
                env!("CARGO_PKG_VERSION"),
                v.to_string_lossy()
            );
        }
        let exe = std::env::current_exe()
            .ok()
            .and_then(|p| std::fs::read(p).ok())
            .map(|b| {
                Sha256::digest(&b)
                    .iter()
                    .map(|x| format!("{x:02x}"))
                    .collect::<String>()
            })
            .unwrap_or_else(|| "unknown-executable".into());
        format!("palpate {} exe {exe}", env!("CARGO_PKG_VERSION"))
    })
}

/// Loads the surrogate of `model` on `loading` in `bounds` from `cache`, or
/// builds it (model runs in parallel with a progress report named `label`)
/// and stores it there. `description` must name everything about the model
/// that its name does not (e.g. `format!("{spec:?}")` of its
/// [`crate::model::ModelSpec`]); the code version is added here.
pub fn load_or_build(
    model: &dyn ForwardModel,
    loading: &Loading,
    bounds: ParamBox,
    options: SurrogateOptions,
    description: &str,
    cache: &Path,
    label: &str,
) -> anyhow::Result<(Surrogate, CacheStatus)> {
    let request = SurrogateRequest {
        model,
        loading,
        bounds,
        options,
        description: format!("{description}; {}", code_version()),
    };
    let key = request.key();
    let path = cache.join(format!("surrogate-{key}.json"));
    if path.exists() {
        match std::fs::read_to_string(&path)
            .map_err(|e| e.to_string())
            .and_then(|t| Surrogate::from_json(&t))
        {
            Ok(s) if s.key() == key => return Ok((s, CacheStatus::Hit(path))),
            Ok(_) => eprintln!(
                "warning: {} holds another surrogate; rebuilding",
                path.display()
            ),
            Err(e) => eprintln!(
                "warning: cannot read the cached surrogate {}: {e}; rebuilding",
                path.display()
            ),
        }
    }
    let total = (request.options.training_runs + request.options.validation_runs) as u64;
    let bar = Progress::new(
        total,
        label,
        "{msg} [{bar:40}] {pos}/{len} model runs ({elapsed}, eta {eta})",
    );
    let tick = |_done: usize, _total: usize| bar.inc(1);
    let built = Surrogate::build(&request, Some(&tick));
    bar.finish();
    let s =
        built.map_err(|e| anyhow::anyhow!("building the surrogate of {}: {e}", model.name()))?;
    write_atomic(&path, s.to_json().as_bytes())?;
    Ok((s, CacheStatus::Built(path)))
}

/// Loads `<cache>/<kind>-<key>.json`, key the SHA-256 of `description` and
/// the code version, or computes the value and stores it there (atomically):
/// the same cache and invalidation as [`load_or_build`], for the FE results
/// a surrogate needs beside its design runs (e.g. the nodule-free R2 pass
/// that `palpate localize` adds the nodules' excess to).
pub fn load_or_compute<T: serde::Serialize + serde::de::DeserializeOwned>(
    kind: &str,
    description: &str,
    cache: &Path,
    compute: impl FnOnce() -> anyhow::Result<T>,
) -> anyhow::Result<(T, CacheStatus)> {
    let text = format!("{kind}; {description}; {}", code_version());
    let key: String = Sha256::digest(text.as_bytes())
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    let path = cache.join(format!("{kind}-{key}.json"));
    if path.exists() {
        match std::fs::read_to_string(&path)
            .map_err(|e| e.to_string())
            .and_then(|t| serde_json::from_str::<T>(&t).map_err(|e| e.to_string()))
        {
            Ok(v) => return Ok((v, CacheStatus::Hit(path))),
            Err(e) => eprintln!(
                "warning: cannot read the cached {kind} {}: {e}; recomputing",
                path.display()
            ),
        }
    }
    let v = compute()?;
    write_atomic(&path, serde_json::to_string(&v)?.as_bytes())?;
    Ok((v, CacheStatus::Built(path)))
}

/// Parses `--box NAME=LO,HI` for every parameter of `model`; the error names
/// the option or the missing parameters (with a suggestion around the law's
/// typical value).
pub fn parse_box(boxes: &[String], model: &dyn ForwardModel) -> anyhow::Result<ParamBox> {
    let space = model.space();
    let mut lower = vec![f64::NAN; space.len()];
    let mut upper = vec![f64::NAN; space.len()];
    for b in boxes {
        let (name, range) = b
            .split_once('=')
            .filter(|(a, r)| !a.is_empty() && !r.is_empty())
            .ok_or_else(|| anyhow::anyhow!("`{b}`: expected NAME=LO,HI, e.g. C10=0.0005,0.002"))?;
        let k = space.index_of(name).ok_or_else(|| {
            anyhow::anyhow!(
                "--box {b}: unknown parameter `{name}` (the model has {})",
                space.names().join(", ")
            )
        })?;
        if !lower[k].is_nan() {
            anyhow::bail!("--box {b}: a box for {name} is given twice; give each parameter once");
        }
        let (lo, hi) = range
            .split_once(',')
            .and_then(|(l, h)| Some((l.trim().parse::<f64>().ok()?, h.trim().parse::<f64>().ok()?)))
            .ok_or_else(|| anyhow::anyhow!("--box {b}: expected NAME=LO,HI with two numbers"))?;
        lower[k] = lo;
        upper[k] = hi;
    }
    let missing: Vec<String> = space
        .params
        .iter()
        .zip(&lower)
        .filter(|(_, l)| l.is_nan())
        .map(|(p, _)| {
            format!(
                "{} (e.g. --box {}={},{})",
                p.name,
                p.name,
                p.initial / 4.0,
                p.initial * 4.0
            )
        })
        .collect();
    if !missing.is_empty() {
        anyhow::bail!(
            "--box: the surrogate is trained inside a box that must hold the posterior; give NAME=LO,HI for {}",
            missing.join(", ")
        );
    }
    ParamBox::new(space, &lower, &upper).map_err(|e| anyhow::anyhow!("--box: {e}"))
}
