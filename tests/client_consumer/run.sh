#!/bin/sh
# Installs the build tree into a temporary prefix, then builds tests/client_consumer against it with
# find_package(fgsr-client) and with pkg-config, and runs both. Usage: run.sh BUILD_DIR SOURCE_DIR
set -eu
build=$1
src=$2
tmp=$(mktemp -d /tmp/fgsr-consumer-XXXXXX)
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" > "$tmp/install.log"
cmake -S "$src/tests/client_consumer" -B "$tmp/build" -DCMAKE_PREFIX_PATH="$tmp/prefix" > "$tmp/configure.log"
cmake --build "$tmp/build" > "$tmp/build.log"
LD_LIBRARY_PATH="$tmp/prefix/lib:$tmp/prefix/lib64:${LD_LIBRARY_PATH:-}" "$tmp/build/consumer_cmake"
pc=$(find "$tmp/prefix" -name fgsr-client.pc | head -n 1)
PKG_CONFIG_PATH=$(dirname "$pc") pkg-config --exists fgsr-client
# pkg-config's prefix is the configured one; point it at the temporary prefix.
cc "$src/tests/client_consumer/main.c" -o "$tmp/consumer_pc" \
   $(PKG_CONFIG_PATH=$(dirname "$pc") pkg-config --define-variable=prefix="$tmp/prefix" --cflags --libs fgsr-client)
LD_LIBRARY_PATH="$tmp/prefix/lib:$tmp/prefix/lib64:${LD_LIBRARY_PATH:-}" "$tmp/consumer_pc"
echo "client_install_consumer: ok"
