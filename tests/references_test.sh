#!/usr/bin/env bash
# Every reference key the code cites ([Owen13, ch. 10], [Welford62, Chan79]) has its entry in
# docs/references.md: a key is the first word of a bracket group that looks like one (a name and
# two digits of a year), or a later word of the group with a lower-case letter (not a section
# such as QK15). Usage: references_test.sh SOURCE_DIR
set -u
root=${1:?source directory}
groups=$(grep -rhoP '\[[A-Z][A-Za-z]+[0-9]{2}[a-z]?(?=[],;])[^]\n]*\]' "$root/src" "$root/web/src")
cited=$( (grep -oP '^\[\K[A-Z][A-Za-z]+[0-9]{2}[a-z]?' <<<"$groups"
    grep -oP '[,;] \K[A-Z]*[a-z][A-Za-z]*[0-9]{2}[a-z]?(?=[],; ])' <<<"$groups") | sort -u)
listed=$(grep -oP '^\| \[\K[A-Za-z0-9]+(?=\])' "$root/docs/references.md" | sort -u)
[ -n "$cited" ] || { echo "references: no key found in $root/src"; exit 1; }
missing=$(comm -23 <(echo "$cited") <(echo "$listed"))
if [ -n "$missing" ]; then
    echo "references: keys cited in the code but not in docs/references.md:"
    for k in $missing; do echo "  [$k] in $(grep -rlF "$k" "$root/src" "$root/web/src" | head -3 | tr '\n' ' ')"; done
    exit 1
fi
echo "references: the $(wc -l <<<"$cited") keys cited in the code are in docs/references.md"
