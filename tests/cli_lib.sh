# cli_lib.sh - what the tool's shell tests share (sourced, not run):
# cli_scratch NAME makes a scratch folder (removed at exit), enters it and
# starts the tallies `failed` and `count`; bad MESSAGE reports the case
# `$name` as failed with the first lines of its err.txt (and `$who`, the
# user it ran as, where a test sets it).
cli_scratch() {
    T=$(mktemp -d "${TMPDIR:-/tmp}/polyc_$1.XXXXXX") || exit 2
    trap 'rm -rf "$T"' EXIT
    cd "$T" || exit 2
    failed=0
    count=0
}
bad() {
    echo "FAIL $name${who:+ ($who)}: $*"
    sed 's/^/    stderr: /' err.txt 2> /dev/null | head -"${CLI_ERR_LINES:-3}"
    failed=$((failed + 1))
}
