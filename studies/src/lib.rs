//! palpate studies: manifests, runner, reports, plots.
