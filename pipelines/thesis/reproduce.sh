#!/usr/bin/env bash
# Reproduces the README's thesis table: trains every pipeline in this folder and validates
# it at its [validate] load scale (full banded, full dense LU and reduced runs, one each).
# Usage: pipelines/thesis/reproduce.sh   (from the repository root, after `cargo build --release`)
set -u
bin=${FLEXROM:-target/release/flexrom}
printf '| pipeline | modes | rel_error | max probe error (m) | full (s) | dense (s) | reduced (s) | vs ours | vs dense |\n|---|---|---|---|---|---|---|---|---|\n'
for f in pipelines/thesis/*.toml; do
  name=$(basename "$f" .toml)
  scale=$(grep -A1 '^\[validate\]' "$f" | tail -1 | sed 's/.*\[\(.*\)\].*/\1/')
  if ! "$bin" train "$f" 2>/dev/null; then echo "| $name | train failed | | | | | | | |"; continue; fi
  if json=$("$bin" validate "$f" --load-scale "$scale" --json 2>/tmp/flexrom-thesis-err); then
    python3 - "$name" "$json" <<'PY'
import json, sys
j = json.loads(sys.argv[2])
print(f"| {sys.argv[1]} | {j['n_modes']} | {j['rel_error']:.2e} | {j['max_probe_error']:.2e} | {j['full_seconds']:.4f} | {j['full_dense_seconds']:.3f} | {j['rom_seconds']:.4f} | {j['speedup']:.2f} | {j['speedup_vs_dense']:.2f} |")
PY
  else
    echo "| $name | fails: $(tail -1 /tmp/flexrom-thesis-err | cut -c1-90) | | | | | | | |"
  fi
done
