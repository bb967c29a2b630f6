#!/usr/bin/env bash
# Makes `import bpm` work in the `python3` on PATH (or $PYTHON): writes bpm.pth into its
# site-packages, naming the folder the module is built in (build/python), so that the module a
# later build makes is the one imported. Where that Python is not Debian's own but of the same
# version and lacks numpy (a pyenv Python, say), the .pth also names Debian's packages folder, where
# install-deps.sh put numpy. Idempotent; run by render-default.sh after the build.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="$(cd "${BPM_BUILD_DIR:-$root/build}" && pwd)"
py="${PYTHON:-python3}"
if ! compgen -G "$build/python/bpm.*.so" >/dev/null; then
  echo "install-python: no module in $build/python (pybind11 or Python's headers missing?)" >&2
  exit 1
fi
version() { "$1" -c 'import sys; print("%d.%d" % sys.version_info[:2])'; }
site="$("$py" - <<'PY'
import os, site, sys
# The first site folder this user may write to (or create), else the user's own.
def writable(d):
    while not os.path.exists(d):
        d = os.path.dirname(d)
    return os.access(d, os.W_OK)
for d in site.getsitepackages():
    if writable(d):
        print(d)
        sys.exit(0)
print(site.getusersitepackages())
PY
)"
mkdir -p "$site"
rm -f "$site/bpm.pth"  # so that what it named before does not decide what it names now
lines="$build/python"
debian=/usr/lib/python3/dist-packages
if ! "$py" -c 'import numpy' 2>/dev/null && [ -x /usr/bin/python3 ] &&
   [ "$(version "$py")" = "$(version /usr/bin/python3)" ] && [ -d "$debian" ]; then
  lines="$lines"$'\n'"$debian"
fi
printf '%s\n' "$lines" > "$site/bpm.pth.tmp"
mv "$site/bpm.pth.tmp" "$site/bpm.pth"
if ! (cd / && "$py" -c 'import bpm, numpy') 2>/dev/null; then
  echo "install-python: $py still cannot import bpm and numpy (its version: $(version "$py"); the module is built for Debian's python3 $(version /usr/bin/python3))" >&2
  exit 1
fi
echo "install-python: $py imports bpm from $build/python ($site/bpm.pth)"
