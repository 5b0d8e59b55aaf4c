//! The options of every command that reads `--data` files, on how to read
//! them: columns chosen by name, the sign convention of compression and the
//! lines before the header. The same keys in brackets
//! (`--data 'uniaxial[force=Load,compression=positive]=FILE'`) set them for
//! one file and take precedence.

use crate::records::ReadOptions;

/// How to read every `--data` file (docs/guide/installing-and-data.md).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct ReadingArgs {
    /// Choose a column of every --data file by name, ROLE=NAME with ROLE one of
    /// time, displacement, force, stretch, strain, true_strain, stress,
    /// true_stress and NAME the column's header with or without its unit
    /// (e.g. --column force=Load --column displacement=Compression). Repeatable.
    #[arg(long = "column", value_name = "ROLE=NAME")]
    pub column: Vec<String>,
    /// How the --data files write compression: negative (strain and stress
    /// negative, palpate's convention), positive (converted), yes (a
    /// compression test, whichever sign: read from the data) or none (a
    /// tension test). Default: read from the data; strain and stress both
    /// positive are compression only when the file says it is a compression
    /// test and the curve stiffens as compression does (otherwise refused as
    /// ambiguous). A declared compression whose curve softens as tension's
    /// does is refused.
    #[arg(long, value_name = "SIGN")]
    pub compression: Option<String>,
    /// Lines at the top of every --data file before its header (kept as
    /// metadata). Default: the header is the first line of names followed by
    /// a row of numbers.
    #[arg(long, value_name = "N")]
    pub skip_rows: Option<usize>,
}

impl ReadingArgs {
    /// The reading options these flags give every file.
    pub fn defaults(&self) -> anyhow::Result<ReadOptions> {
        let mut o = ReadOptions::default();
        for c in &self.column {
            let (role, name) = c
                .split_once('=')
                .filter(|(r, n)| !r.trim().is_empty() && !n.trim().is_empty())
                .ok_or_else(|| {
                    anyhow::anyhow!("--column {c}: expected ROLE=NAME, e.g. force=Load")
                })?;
            anyhow::ensure!(
                crate::records::Role::parse(role).is_some(),
                "--column {c}: unknown role `{role}`; expected one of {}",
                crate::records::Role::ALL.map(|r| r.key()).join(", ")
            );
            o.set(role, name)
                .map_err(|e| anyhow::anyhow!("--column {c}: {e}"))?;
        }
        if let Some(s) = &self.compression {
            o.set("compression", s)
                .map_err(|e| anyhow::anyhow!("--compression {e}"))?;
        }
        o.skip_rows = self.skip_rows;
        Ok(o)
    }
}
