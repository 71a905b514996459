# shellcheck shell=sh
# Shell functions on float PFM renders, for the scripts that compare
# renders (sourced: . scripts/pfm.sh).

# pfm_samples FILE OUT: the file's float samples, one per line, into OUT
# (the three header lines skipped; od prints the samples as floats).
pfm_samples() {
    pfm_head=$(head -n 3 "$1" | wc -c)
    tail -c +"$((pfm_head + 1))" "$1" | od -An -v -f | tr -s ' ' '\n' | sed '/^$/d' >"$2"
}
