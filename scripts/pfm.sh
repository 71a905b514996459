# shellcheck shell=sh
# Shell functions on float PFM renders, for the scripts that compare
# renders (sourced: . scripts/pfm.sh).

# pfm_samples FILE OUT: the file's float samples, one per line, into OUT
# (the three header lines skipped; od prints the samples as floats).
pfm_samples() {
    pfm_head=$(head -n 3 "$1" | wc -c)
    tail -c +"$((pfm_head + 1))" "$1" | od -An -v -f | tr -s ' ' '\n' | sed '/^$/d' >"$2"
}

# pfm_rmse A B DIR: the RMSE of the samples of two PFM files of one size
# (linear RGB), printed with 3 digits; scratch files in DIR.
pfm_rmse() {
    pfm_samples "$1" "$3/pfm_rmse_a.txt"
    pfm_samples "$2" "$3/pfm_rmse_b.txt"
    paste "$3/pfm_rmse_a.txt" "$3/pfm_rmse_b.txt" |
        awk '{ d = $1 - $2; s += d * d; n++ } END { printf "%.3g\n", n ? sqrt(s / n) : 0 }'
}
