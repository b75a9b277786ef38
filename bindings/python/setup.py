"""setup.py - builds the polyc package: polyc/__init__.py and polyc/libpolyc.so.

libpolyc.so is a plain shared library (loaded with ctypes, not a CPython
extension module): the library (src/*.c, src/*/*.c), the polyc tool's readers
(tools/scanlog.c, tools/scanlog_noreturn.c, tools/mapfile.c, tools/mapfile_pgm.c,
tools/mapfile_png.c, tools/mapfile_image.c, tools/inflate.c,
tools/gridimage.c, tools/readfile.c, tools/textesc.c) and the binding's glue
(polyc_io.c), compiled with the compiler Python was built with. The C
sources are the repository's own (../../src from here): pip builds a local
folder in place, so `pip install ./bindings/python` and `pip install .` at
the repository root (whose setup.py runs this one) both reach them. The
metadata is in pyproject.toml; the version is polyc.h's.
"""
import glob
import os
import re
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
HEADER = os.path.join(REPO, "include", "polyc.h")
if not os.path.exists(HEADER):
    sys.exit("setup.py: %s not found: build the package from a checkout of libpolyc "
             "(bindings/python inside it)" % HEADER)


def _version():
    text = open(HEADER).read()
    parts = [re.search(r"#define POLYC_VERSION_%s (\d+)" % p, text).group(1)
             for p in ("MAJOR", "MINOR", "PATCH")]
    return ".".join(parts)


# The repository's C sources, given to the compiler as absolute paths at
# build time (setup() takes only paths inside its own folder; the objects go
# under build_temp, never into src/)
REPO_SOURCES = (sorted(glob.glob(os.path.join(REPO, "src", "*.c")) +
                       glob.glob(os.path.join(REPO, "src", "*", "*.c"))) +
                [os.path.join(REPO, "tools", n)
                 for n in ("scanlog.c", "scanlog_noreturn.c", "mapfile.c", "mapfile_pgm.c",
                           "mapfile_png.c", "mapfile_image.c", "inflate.c", "gridimage.c",
                           "readfile.c", "textesc.c")])
REPO_HEADERS = [HEADER] + sorted(glob.glob(os.path.join(REPO, "src", "*.h")) +
                                 glob.glob(os.path.join(REPO, "tools", "*.h")))


class BuildSharedLibrary(build_ext):
    """build_ext for a library that ctypes loads: named libpolyc.so (no ABI
    tag), no PyInit_ symbol, the Makefile's C flags."""

    def get_ext_filename(self, fullname):
        suffix = {"darwin": ".dylib", "win32": ".dll"}.get(sys.platform, ".so")
        return os.path.join(*fullname.split(".")) + suffix

    def get_export_symbols(self, ext):
        return []

    def build_extension(self, ext):
        ext.sources = list(ext.sources) + [p for p in REPO_SOURCES if p not in ext.sources]
        ext.depends = list(ext.depends) + REPO_HEADERS
        if self.compiler.compiler_type == "unix":
            ext.extra_compile_args = ["-std=c99", "-O2", "-fvisibility=hidden", "-fno-math-errno"]
        super().build_extension(ext)


LIBRARY = Extension(
    "polyc.libpolyc",
    sources=[os.path.relpath(os.path.join(HERE, "polyc_io.c"))],   # + REPO_SOURCES
    include_dirs=[os.path.join(REPO, "include"), os.path.join(REPO, "tools")],
    define_macros=[("POLYC_BUILD_SHARED", None), ("_POSIX_C_SOURCE", "200809L")],
    libraries=["m"] if sys.platform != "win32" else [],
)

setup(
    version=_version(),
    packages=["polyc"],
    package_dir={"polyc": os.path.relpath(os.path.join(HERE, "polyc"))},
    ext_modules=[LIBRARY],
    cmdclass={"build_ext": BuildSharedLibrary},
    zip_safe=False,
    # setuptools' work files: not the Makefile's build/ when run from the root
    options={"build": {"build_base": os.path.join("build", "setuptools")}},
)
