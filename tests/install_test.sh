#!/bin/sh
# install_test.sh - `make install` into a temporary prefix, then a small C
# program built against the installed copy with `pkg-config --cflags --libs
# polyc` must compile, load the installed libpolyc.so (found through the
# rpath that polyc.pc gives, without LD_LIBRARY_PATH) and map a scan. Also
# checks that libpolyc.so exports the polyc_ API and nothing else.
# usage: tests/install_test.sh MAKE BUILD
set -eu
make=${1:-make}
build=${2:-build}
cc=${CC:-cc}
fail() { echo "install_test: FAIL: $*"; exit 1; }
command -v pkg-config >/dev/null || fail "pkg-config is not installed"

extra=$(nm -D --defined-only "$build/libpolyc.so" | awk '{print $3}' | grep -v '^polyc_[a-z]' || true)
[ -z "$extra" ] || fail "libpolyc.so exports more than the API: $extra"
for f in $(sed -n 's/^POLYC_API[^(]*[ *]\(polyc_[a-z_]*\)(.*/\1/p' include/polyc.h); do
    nm -D --defined-only "$build/libpolyc.so" | grep -q " $f\$" || fail "$f is not exported"
done

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/usr
$make --no-print-directory install BUILD="$build" PREFIX="$prefix" >"$tmp/install.log" 2>&1 ||
    { cat "$tmp/install.log"; fail "make install"; }
for f in include/polyc.h lib/libpolyc.a lib/libpolyc.so lib/pkgconfig/polyc.pc bin/polyc; do
    [ -e "$prefix/$f" ] || fail "$f not installed"
done
soname=$(readelf -d "$prefix/lib/libpolyc.so" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')
[ -n "$soname" ] && [ -e "$prefix/lib/$soname" ] || fail "soname link '$soname' missing"

cat >"$tmp/use.c" <<'C'
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <polyc.h>

int main(void)
{
    float r[91];
    for (int i = 0; i < 91; i++)
        r[i] = (float)(2.0 / cos(-0.785398 + 0.0174533 * i));
    polyc_scan scan = {0, 0, 0, -0.785398f, 0.0174533f, 0.02f, 30.0f, 91, 0, r};
    polyc_config cfg;
    polyc_limits lim;
    polyc_ctx *ctx;
    polyc_config_default(&cfg);
    if (polyc_version() != POLYC_VERSION || polyc_limits_for_scans(&cfg, &scan, 1, &lim))
        return 1;
    size_t size = polyc_memory_size(&cfg, &lim);
    void *block = malloc(size);
    if (!block || polyc_init(block, size, &cfg, &lim, &ctx) || polyc_add_scan(ctx, &scan) ||
        polyc_build(ctx, NULL, NULL) || polyc_polyline_count(ctx) < 1)
        return 1;
    printf("use: libpolyc %u, %u polylines\n", (unsigned)polyc_version(),
           (unsigned)polyc_polyline_count(ctx));
    free(block);
    return 0;
}
C
export PKG_CONFIG_PATH="$prefix/lib/pkgconfig"
flags=$(pkg-config --cflags --libs polyc) || fail "pkg-config does not know polyc"
# shellcheck disable=SC2086 # the flags are words
$cc -std=c99 -Wall -Wextra -Werror "$tmp/use.c" -o "$tmp/use" $flags -lm || fail "compile with: $flags"
# as a user runs it: no LD_LIBRARY_PATH, no ldconfig (polyc.pc's rpath)
env -u LD_LIBRARY_PATH ldd "$tmp/use" | grep -q "$prefix/lib/$soname" ||
    fail "the program does not load the installed $soname without LD_LIBRARY_PATH"
env -u LD_LIBRARY_PATH "$tmp/use" || fail "the program failed"
"$prefix/bin/polyc" --version >/dev/null || fail "installed polyc does not run"
echo "install_test: ok: $(pkg-config --modversion polyc), $flags, $soname"
