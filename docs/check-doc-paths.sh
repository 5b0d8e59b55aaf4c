#!/usr/bin/env bash
# Fails when a backticked repository path cited in docs/**/*.md or README.md
# does not exist in the tree. Ignores docs/notes/ (dated research notes) and
# CHANGELOG.md (history); a path under ../shared (the team's data folder, not
# part of the repository) is not checked.
#
# A cited path is a backticked word that starts with a top-level entry of the
# repository (a directory followed by '/', or a file at the root) and has no
# space, glob or placeholder in it, e.g. `forward/fe/src/system.rs`,
# `studies/treloar.toml`, `docs/theory.md`. A trailing `:LINE`, `:LINE-LINE`,
# `#anchor` or `::item` is dropped. Run from anywhere inside the repository.
set -euo pipefail
cd "$(git rev-parse --show-toplevel)"

tops=$(git ls-files | sed 's#/.*##' | sort -u | sed 's/\./\\./g' | paste -sd'|')
report=$(while IFS= read -r doc; do
  # every backticked span on one line, then keep those that look like paths
  grep -no '`[^`]*`' "$doc" | while IFS= read -r hit; do
    line=${hit%%:*}
    path=${hit#*:}; path=${path//\`/}
    path=${path%%#*}; path=${path%%::*}
    [[ $path =~ ^(.*):[0-9]+(-[0-9]+)?$ ]] && path=${BASH_REMATCH[1]}
    [[ $path =~ ^($tops)(/|$) ]] || continue
    [[ $path =~ [[:space:]\*\?\<\>\{\}\$] ]] && continue
    [[ -e $path ]] || echo "$doc:$line: \`$path\` does not exist"
  done
done < <(git ls-files -- 'docs/*.md' README.md | grep -v '^docs/notes/'))
[[ -z $report ]] && exit 0
printf '%s\n' "$report" >&2
echo "$(wc -l <<<"$report") cited path(s) missing" >&2
exit 1
