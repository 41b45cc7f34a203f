#!/bin/sh
# `cmake --install` into a temporary prefix, the prefix moved elsewhere, then an example run end
# to end with the moved `mresim`: it must find its plotting scripts in <prefix>/share/mresim/python
# through its own location, not in the source tree it was built from.
# Usage: relocated_install_test.sh BUILD_DIR SOURCE_DIR
set -eu
build=$(cd "$1" && pwd)
source=$(cd "$2" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "install_relocated: FAIL: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$tmp/prefix" > "$tmp/install.log" || fail "cmake --install"
for f in bin/mresim lib/libmresim.a include/mresim/core/version.hpp \
         include/mresim/app/progress.hpp share/mresim/python/mresim_plot.py \
         share/mresim/python/mresim_plots/__init__.py; do
  [ -f "$tmp/prefix/$f" ] || fail "not installed: $f"
done
grep -q kVersion "$tmp/prefix/include/mresim/core/version.hpp" || fail "version.hpp incomplete"

# Relocated: nothing may point at the prefix it was installed to.
mv "$tmp/prefix" "$tmp/moved"
unset MRESIM_PYTHON_DIR
moved_scripts="$tmp/moved/share/mresim/python"
"$tmp/moved/bin/mresim" plot --help > "$tmp/help.txt"
grep -q "Plotting scripts: $moved_scripts\$" "$tmp/help.txt" ||
  fail "the moved mresim does not use $moved_scripts: $(grep 'Plotting scripts' "$tmp/help.txt")"
# The override still wins.
MRESIM_PYTHON_DIR=/elsewhere "$tmp/moved/bin/mresim" plot --help | grep -q "Plotting scripts: /elsewhere$" ||
  fail "MRESIM_PYTHON_DIR does not override"

cd "$tmp"
"$tmp/moved/bin/mresim" run "$source/examples/fig2_2_single_spring_axial.toml" --out "$tmp/run" \
  > "$tmp/run.out" 2> "$tmp/run.err" || fail "run: $(cat "$tmp/run.err")"
[ -f "$tmp/run/results.h5" ] || fail "no results.h5"
ls "$tmp/run/figures/"*.png > /dev/null 2>&1 || fail "no figures: $(cat "$tmp/run.out" "$tmp/run.err")"
grep -q "wrote .* figure" "$tmp/run.out" || fail "the plotting script said nothing"
echo "install_relocated: ok ($(ls "$tmp/run/figures" | wc -l) figures)"

# The Python module (when built): imported from the moved prefix, it runs the same example and
# draws its figures with the prefix's plotting scripts.
init=$(find "$tmp/moved" -path '*/mresim/__init__.py' | head -n 1)
if [ -n "$init" ]; then
  package_dir=$(dirname "$(dirname "$init")")
  PYTHONPATH="$package_dir" /usr/bin/python3 - "$source/examples/fig2_2_single_spring_axial.toml" \
    "$tmp/python-run" "$moved_scripts" > "$tmp/python.out" 2>&1 <<'PY' || fail "python: $(cat "$tmp/python.out")"
import os, pathlib, sys
import mresim
assert os.environ["MRESIM_PYTHON_DIR"] == sys.argv[3], os.environ.get("MRESIM_PYTHON_DIR")
results = mresim.run(pathlib.Path(sys.argv[1]), out=sys.argv[2], plot=True)
assert results.cases[0]["field"].size > 0
assert list(pathlib.Path(sys.argv[2], "figures").glob("*.png")), "no figures"
PY
  echo "install_relocated: the installed Python module ran the example"
else
  echo "install_relocated: no Python module installed (MRESIM_BUILD_PYTHON=OFF)"
fi
