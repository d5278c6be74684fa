#!/bin/sh
# The architecture rules of docs/ARCHITECTURE.md, checked on the source tree and the built daemon:
#   1. no file under protocol/, daemon/ or client/ includes a header that lives under tools/;
#   2. fgsrd does not link libpng (image files are a tools concern);
#   3. no source file outside tests/ is over 800 lines.
# (That no target of those folders links a tools/ target is checked when CMake configures: see
# fgsr_check_layers in the top-level CMakeLists.txt.) Usage: check.sh SOURCE_DIR BUILD_DIR
set -eu
src=$1
build=$2
fail=0

# 1. Headers that tools/ provides (fgsr/<path> under any tools/**/include/), included from below.
tools_headers=$(cd "$src/tools" && find . -path '*/include/*' \( -name '*.hpp' -o -name '*.h' \) |
                sed 's#.*/include/##')
[ -n "$tools_headers" ] || { echo "check: found no headers under tools/*/include (layout changed?)"; exit 1; }
for h in $tools_headers; do
    hits=$(grep -rlF "#include <$h>" "$src/protocol" "$src/daemon" "$src/client" 2>/dev/null || true)
    if [ -n "$hits" ]; then
        echo "layering: <$h> (tools/) is included by:" $hits
        fail=1
    fi
done
hits=$(grep -rlE '#include "(\.\./)+tools/' "$src/protocol" "$src/daemon" "$src/client" 2>/dev/null || true)
if [ -n "$hits" ]; then echo "layering: relative includes into tools/ in:" $hits; fail=1; fi

# 2. The daemon's shared-library dependencies.
if ldd "$build/bin/fgsrd" | grep -q 'libpng'; then
    echo "layering: build/bin/fgsrd links libpng:"; ldd "$build/bin/fgsrd" | grep libpng
    fail=1
fi

# 3. File size: over 800 lines is a file that owns too much.
long=$(cd "$src" && find protocol daemon client shaders tools \
        \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' -o -name '*.c' -o -name '*.comp' \) \
        -exec wc -l {} + | awk '$2 != "total" && $1 > 800 {print $2 " (" $1 " lines)"}')
if [ -n "$long" ]; then echo "size: source files over 800 lines:"; echo "$long"; fail=1; fi

[ $fail -eq 0 ] && echo "layers: ok"
exit $fail
