#!/usr/bin/env bash
# The installed tool, away from any checkout: every command the README's first steps use.
#
#   .ci/installed_smoke.sh [CLONE]      (default: the clone holding this script)
#
# Installs CLONE into a fresh virtual environment (no extras, not editable), then runs each
# command below from a temporary folder outside the clone.  Each must exit 0 and print no
# Python traceback on stderr; each is printed with its wall time.  Stops at the first
# failure, naming the command, with its exit status and the end of its output (exit 1).
#
# The clone's files (tracked and untracked, not ignored) are copied first and installed from
# that copy, so that the build leaves no build/ folder in the clone and an old build/ there
# cannot slip stale files into the wheel.
set -euo pipefail

clone=$(cd "${1:-$(dirname "$0")/..}" && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/pendverify-smoke.XXXXXX")
trap 'rm -rf "$work"' EXIT

now() { date +%s.%N; }
seconds() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.1f", b - a }'; }

# step COMMAND...: run it, print it and its wall time; stop on a non-zero status or a traceback
step() {
    local start rc=0
    printf '$ %s\n' "$*"
    start=$(now)
    "$@" >"$work/out" 2>"$work/err" || rc=$?
    if [ "$rc" -ne 0 ] || grep -q "Traceback" "$work/err"; then
        echo "FAILED (exit status $rc$(grep -q Traceback "$work/err" && echo ', a traceback on stderr')): $*"
        echo "--- end of stdout"; tail -n 20 "$work/out"
        echo "--- end of stderr"; tail -n 40 "$work/err"
        exit 1
    fi
    echo "  ok, $(seconds "$start" "$(now)") s"
}

src="$work/src"
mkdir -p "$src"
if git -C "$clone" rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    # (files deleted but not yet committed are skipped: the copy is the work tree as it is)
    git -C "$clone" ls-files -z --cached --others --exclude-standard \
        | (cd "$clone" && tar --null --files-from=- --ignore-failed-read -cf - 2>/dev/null) \
        | tar -C "$src" -xf -
else
    cp -R "$clone/." "$src"
    rm -rf "$src/build" "$src/.venv"
fi

echo "installing $clone into a fresh virtual environment ($work/venv)"
start=$(now)
python3 -m venv "$work/venv"
"$work/venv/bin/pip" install --quiet --upgrade pip
"$work/venv/bin/pip" install --quiet "$src"
echo "  installed, $(seconds "$start" "$(now)") s"
rm -rf "$src"

export PATH="$work/venv/bin:$PATH"
mkdir "$work/run"
cd "$work/run"

# shipped data, located in the installed package (never in the clone)
shipped() { python -c "import importlib.resources as r; print(r.files('pendverify.$1') / '$2')"; }
scene=$(shipped scenes damped_double_pendulum.toml)
sweep_200=$(shipped sweeps double_pendulum_200.toml)
case "$scene$sweep_200" in "$clone"/*) echo "FAILED: the shipped data resolves into the clone ($scene)"; exit 1 ;; esac

step pendverify check
step pendverify keygen -o keys
step pendverify example double_pendulum reference
step pendverify certify reference/analytic/params/double_pendulum.toml -o certs --key keys/pendverify-signing.key.pem
step pendverify recheck certs/double_pendulum.cert.json --trust keys/pendverify-signing.pub.pem
# a typo in the LaTeX model (2\delta for \delta in M's last entry): the diagnosis repairs it
sed 's/& \\delta \\end{bmatrix}/\& 2\\delta \\end{bmatrix}/g' reference/examples/double_pendulum_latex.toml >typo.toml
step python -c 'import sys, pendverify; r = pendverify.check("typo.toml", "reference/urdf/double_pendulum.urdf", "reference/analytic/params/double_pendulum.toml"); sys.exit(r.passed or not any(f.kind == "repair" and f.details["checks_pass"] for fs in r.diagnoses.values() for f in fs))'
step python -c 'import pendverify, sys; sys.exit(not pendverify.certify_set("api-certs", "reference/analytic/params/double_pendulum.toml", samples=200).certified)'

sed 's/^count = 200$/count = 20/' "$sweep_200" >sweep_20.toml
grep -q '^count = 20$' sweep_20.toml || { echo "FAILED: could not set count = 20 in $sweep_200"; exit 1; }
step pendverify certify --sweep sweep_20.toml -o sweep-certs --workers 2
[ "$(ls sweep-certs/*.cert.json | wc -l)" -eq 20 ] || { echo "FAILED: the sweep wrote $(ls sweep-certs/*.cert.json | wc -l) certificates, not 20"; exit 1; }

step pendverify simulate "$scene" -o run.npz
step pendverify render "$scene" -o animation.html
step pendverify report -o review
step pendverify stress --quick
step pendverify bench certify
step pendverify example cart_pole cart_pole
step pendverify check --analytic cart_pole/examples/cart_pole.py --urdf cart_pole/examples/cart_pole.urdf --params cart_pole/examples/cart_pole.toml
step pendverify simulate cart_pole/scenes/cart_pole_lqr_push.toml
# the shipped MJCF, compiled by MuJoCo (a dependency, no extra): shown, then checked
mjcf=$(shipped examples double_pendulum.mjcf.xml)
step pendverify show --robot "$mjcf"
step pendverify check --model double_pendulum --urdf "$mjcf"
# the MATLAB form of a worked example, and the verified model exported as C (compiled) and NumPy
step pendverify example minimal_double_pendulum minimal
step pendverify check --analytic minimal/examples/minimal_double_pendulum_matlab.toml --urdf minimal/urdf/double_pendulum.urdf --params minimal/examples/minimal_double_pendulum.toml
step pendverify export minimal/examples/minimal_double_pendulum_matlab.toml --lang c -o exported --urdf minimal/urdf/double_pendulum.urdf --params minimal/examples/minimal_double_pendulum.toml
grep -q "Verification: pendverify check of the written code: all checks pass" exported/minimal_double_pendulum.c || { echo "FAILED: the exported C code is not verified"; exit 1; }
step pendverify export double_pendulum --lang numpy -o exported --urdf reference/urdf/double_pendulum.urdf
step python -m pendverify --version
echo "installed smoke test passed"
