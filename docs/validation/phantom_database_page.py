#!/usr/bin/env python3
"""Writes docs/validation/phantom-database.md from a run of
studies/phantom-database.toml: the page's head (phantom-database.head.md,
what the run cannot say: how the database's curve was found, the
conventions) followed by the run's report.md, and the plots the page shows
copied into docs/validation/phantom-database/.

Usage, from the repository's root:

    cargo run -p palpate-studies --bin palpate -- run studies/phantom-database.toml --out runs/phantom-database
    python3 docs/validation/phantom_database_page.py runs/phantom-database

Only the standard library. The page is a function of the run's report and
the head: a rerun of the study (byte-identical) rewrites it unchanged.
"""

import pathlib
import re
import shutil
import sys

HERE = pathlib.Path(__file__).resolve().parent
PAGE = HERE / "phantom-database.md"
HEAD = HERE / "phantom-database.head.md"
PLOTS = HERE / "phantom-database"
# The plots shown on the page; the others stay in the run folder.
SHOWN = ["modulus-modulus.svg", "modulus-interaction.svg", "EF10_0T-fits.svg", "EF30_50T-fits.svg"]


def main(run: pathlib.Path) -> None:
    report = (run / "report.md").read_text()
    missing = [p for p in SHOWN if not (run / "plots" / p).is_file()]
    if missing:
        sys.exit(f"{run}/plots lacks {', '.join(missing)}: is it a run of studies/phantom-database.toml?")
    if PLOTS.exists():
        shutil.rmtree(PLOTS)
    PLOTS.mkdir()
    for p in SHOWN:
        shutil.copyfile(run / "plots" / p, PLOTS / p)

    def image(m: re.Match) -> str:
        alt, file = m.group(1), m.group(2)
        if file in SHOWN:
            return f"![{alt}](phantom-database/{file})"
        return f"(plot: `plots/{file}` of the run folder)"

    report = re.sub(r"!\[([^\]]*)\]\(plots/([^)]+)\)", image, report)
    # the report's headings one level down, under the page's own
    report = re.sub(r"^(#+) ", lambda m: "#" + m.group(1) + " ", report, flags=re.M)
    PAGE.write_text(HEAD.read_text().rstrip("\n") + "\n\n---\n\n" + report)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(pathlib.Path(sys.argv[1]))
