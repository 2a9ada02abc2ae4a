# Sourced by build.sh, sanitize.sh and fuzz.sh: compile through ccache when it is installed (install-deps.sh
# installs it). The base dir and no hashed working directory let a fresh clone in another folder (CI) hit the
# objects a previous build left in ~/.cache/ccache.
if command -v ccache >/dev/null; then
  export CMAKE_CXX_COMPILER_LAUNCHER=ccache
  export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=1 CCACHE_MAXSIZE="${CCACHE_MAXSIZE:-5G}"
fi
