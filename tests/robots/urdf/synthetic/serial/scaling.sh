#!/usr/bin/env bash
# The scaling figures of the README ("Recursions, not energies"): for each chain of N
# joints written by gen.py beside this script (N = 2..12), a scratch crate
# in $SCRATCH (default /tmp/moreau-scaling) holding that one model (file
# form, one constraint on the last link), expanded and built in release
# with one job. Prints N, the fused evaluation's operation count, the
# macro's expansion time (MOREAU_TIMINGS) and the wall time of the crate's
# own release build (its dependencies built beforehand). CasADi's side of
# the same table: casadi_scaling.py beside this script.
#
#     tests/robots/urdf/synthetic/serial/scaling.sh [N ...]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../../../../.." && pwd)"
scratch="${SCRATCH:-/tmp/moreau-scaling}"
export CARGO_TARGET_DIR="$scratch/target"
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(2 3 4 5 6 7 8 9 10 11 12)
printf '| joints | operations | expansion | release build |\n|---:|---:|---:|---:|\n'
for n in "${sizes[@]}"; do
    crate="$scratch/serial_$n"
    mkdir -p "$crate/src" "$crate/models"
    cp "$here/serial_$n.urdf" "$crate/models/"
    cat > "$crate/models/serial_$n.yaml" <<YAML
name: Serial$n
urdf: models/serial_$n.urdf
constraints:
  - name: floor
    h: position_z(l$n, 0.02, -0.01, 0.1) + 0.5
restitution: 0.5
YAML
    cat > "$crate/Cargo.toml" <<TOML
[package]
name = "serial_$n"
version = "0.1.0"
edition = "2024"
publish = false

[dependencies]
moreau = { path = "$repo" }

[workspace]
TOML
    cat > "$crate/src/main.rs" <<RS
use moreau::Model;
moreau::model!(file = "models/serial_$n.yaml");
fn main() {
    println!("{}", <Serial$n<f64> as Model<$n, 1>>::INFO.op_count);
}
RS
    # the dependencies first, then the crate alone
    (cd "$crate" && cargo build --release -j 1 -q 2>/dev/null || true)
    touch "$crate/src/main.rs"
    start=$(date +%s.%N)
    log=$(cd "$crate" && MOREAU_TIMINGS=1 cargo build --release -j 1 -vv 2>&1)
    end=$(date +%s.%N)
    ops=$("$CARGO_TARGET_DIR/release/serial_$n")
    expansion=$(grep -o 'expanded in [0-9.]* ms' <<<"$log" | tail -1 | awk '{print $3}')
    printf '| %d | %d | %.2f s | %.1f s |\n' "$n" "$ops" "$(echo "$expansion / 1000" | bc -l)" "$(echo "$end - $start" | bc -l)"
done
