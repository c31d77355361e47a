#!/usr/bin/env bash
# Fetches Unity (ThrowTheSwitch, MIT) for the firmware test suites from the
# PyPI wheel vyperling==0.0.4, pinned by hash, and extracts unity.c, unity.h
# and unity_internals.h into build/unity/. Unity is never committed.
set -euo pipefail
cd "$(dirname "$0")/.."

OUT=${UNITY_DIR:-build/unity}
VERSION=0.0.4
WHEEL=vyperling-$VERSION-py3-none-any.whl
SHA256=028f4419cf4f49cfaed51256290718753a78cc035923fbf43acc8bcd62d205cb
FILES=(unity.c unity.h unity_internals.h)

if [ -f "$OUT/.stamp" ] && [ "$(cat "$OUT/.stamp")" = "$SHA256" ]; then
    exit 0
fi

if [ -n "${PYTHON:-}" ]; then PY=$PYTHON
elif [ -x .venv/bin/python ]; then PY=.venv/bin/python
else PY=python3
fi

mkdir -p "$OUT/wheel"
printf 'vyperling==%s --hash=sha256:%s\n' "$VERSION" "$SHA256" > "$OUT/requirements.txt"
"$PY" -m pip download -q --no-deps --require-hashes -r "$OUT/requirements.txt" -d "$OUT/wheel"
echo "$SHA256  $OUT/wheel/$WHEEL" | sha256sum -c --quiet -

"$PY" - "$OUT/wheel/$WHEEL" "$OUT" "${FILES[@]}" <<'PYEOF'
import sys, zipfile, pathlib
wheel, out, names = sys.argv[1], pathlib.Path(sys.argv[2]), sys.argv[3:]
with zipfile.ZipFile(wheel) as z:
    for name in names:
        (out / name).write_bytes(z.read("vyperling/c/" + name))
PYEOF
echo "$SHA256" > "$OUT/.stamp"
echo "fetch_unity: Unity from vyperling==$VERSION in $OUT"
