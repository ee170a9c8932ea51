#!/usr/bin/env bash
# Reproduces the thesis table (docs/thesis.md): trains every pipeline in this folder and
# validates it at the middle of its [validate] load scales, the thesis load (full banded, full dense LU and reduced runs,
# one each), printing one Markdown row per pipeline on stdout.
# Usage: pipelines/thesis/reproduce.sh   (from the repository root, after `cargo build --release`)
#
# Stops at the first failure with the command, its exit code and its messages, and exits
# non-zero. The plain whole-system reduction (fourbar_whole_system*.toml without
# `stabilized`) is the thesis's negative result: its validation is expected to fail in the
# first step (docs/whole-system.md), and the row says so; should it ever succeed, that is a
# change to look at and stops the script too.
set -euo pipefail
bin=${FLEXROM:-target/release/flexrom}
expected_to_fail="fourbar_whole_system fourbar_whole_system_raw"
[ -x "$bin" ] || { echo "reproduce.sh: $bin not found or not executable; run cargo build --release first" >&2; exit 1; }
err=$(mktemp "${TMPDIR:-/tmp}/flexrom-thesis.XXXXXX")
trap 'rm -f "$err"' EXIT
fail() {
  echo "reproduce.sh: FAILED: $1" >&2
  sed 's/^/  | /' "$err" >&2
  exit 1
}
files=(pipelines/thesis/*.toml)
printf '| pipeline | modes | rel_error | max probe error (m) | full (s) | dense (s) | reduced (s) | vs ours | vs dense |\n|---|---|---|---|---|---|---|---|---|\n'
i=0
for f in "${files[@]}"; do
  i=$((i + 1))
  name=$(basename "$f" .toml)
  # the middle of the [validate] list: the thesis load (0.935 of [0.9, 0.935, 1.0], 1.0 of [1.0])
  list=$(grep -A1 '^\[validate\]' "$f" | tail -1 | sed -n 's/^load_scales *= *\[\(.*\)\].*/\1/p' | tr -d ' ')
  IFS=, read -r -a loads <<<"$list"
  [ "${#loads[@]}" -gt 0 ] || { : >"$err"; fail "$f: no [validate] load_scales = [...] line to take the load scale from"; }
  scale=${loads[$(( ${#loads[@]} / 2 ))]}
  echo "[$i/${#files[@]}] $name: train, validate at load scale $scale" >&2
  "$bin" -q train "$f" 2>"$err" || fail "flexrom train $f (exit $?)"
  cat "$err" >&2
  set +e
  json=$("$bin" -q validate "$f" --load-scale "$scale" --json 2>"$err")
  code=$?
  set -e
  cat "$err" >&2
  case " $expected_to_fail " in
    *" $name "*)
      [ "$code" -ne 0 ] || fail "$name was expected to fail (docs/whole-system.md) but validated: update this script and docs/thesis.md"
      echo "| $name | fails as expected: $(tail -1 "$err" | cut -c1-90) | | | | | | | |"
      continue
      ;;
  esac
  [ "$code" -eq 0 ] || fail "flexrom validate $f --load-scale $scale (exit $code)"
  python3 - "$name" "$json" <<'PY' || fail "reading the JSON of flexrom validate $f"
import json, sys
j = json.loads(sys.argv[2])
def num(key, fmt):
    v = j.get(key)
    return "—" if v is None else format(v, fmt)
print(f"| {sys.argv[1]} | {j['n_modes']} | {num('rel_error', '.2e')} | {num('max_probe_error', '.2e')} | "
      f"{num('full_seconds', '.4f')} | {num('full_dense_seconds', '.3f')} | {num('rom_seconds', '.4f')} | "
      f"{num('speedup', '.2f')} | {num('speedup_vs_dense', '.2f')} |")
PY
done
echo "reproduce.sh: all ${#files[@]} pipelines done" >&2
