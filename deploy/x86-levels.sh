# The x86-64 psABI levels pathlab is built for beside its baseline, and the extensions (as
# /proc/cpuinfo lists them) whose absence rules a level out at once. Sourced by
# deploy/build-variants.sh and bench/run.sh.

# x86_level_missing LEVEL: the extensions LEVEL needs that this CPU lacks, each after a space
# (nothing when it has them all).
x86_level_missing() {
    local flags missing="" flag
    case "$1" in
        x86-64-v3) flags="avx2 fma bmi2 movbe" ;;
        x86-64-v4) flags="avx512f avx512bw avx512dq avx512vl" ;;
        *) echo "x86_level_missing: unknown level $1" >&2; return 1 ;;
    esac
    for flag in $flags; do
        grep -qw "$flag" /proc/cpuinfo 2>/dev/null || missing="$missing $flag"
    done
    printf '%s' "$missing"
}
