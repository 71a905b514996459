/* agf.c -- reading glasses from Zemax AGF catalog text.
 *
 * An AGF file is a list of glasses, one line per record, the record type
 * in the first two letters:
 *
 *   NM name formula MIL nd vd ...   starts a glass
 *   CD c0 c1 ... c9                 dispersion coefficients
 *   LD lambda_min lambda_max        data range, micrometres
 *   IT lambda tau thickness         internal transmittance tau of a sample
 *                                   `thickness` mm thick, lambda in um
 *
 * Those are read; every other line (CC, GC, ED, TD, OD, BD, blank,
 * unknown) is skipped.  AGF formula numbers read: 1 Schott (CD a0..a5),
 * 2 Sellmeier 1 (CD K1 L1 K2 L2 K3 L3, stored as B1 B2 B3 C1 C2 C3),
 * 5 Conrady (CD n0 A B).  Any other formula is kept with its raw CD values
 * as LP_FORMULA_UNSUPPORTED and agf_formula set.  Every glass needs a CD
 * line with at least the coefficients its formula uses (6, 6, 3).
 *
 * Transmittance tables are normalized when a glass ends:
 *   - a reading tau = 0 becomes LP__TAU_OPAQUE at its own thickness;
 *   - every reading is converted to one reference thickness, that of the
 *     glass's first IT line: tau_ref = tau^(d_ref / d);
 *   - the readings are sorted by wavelength; of several readings at the
 *     same wavelength (different thicknesses) the one with the largest
 *     tau * d is kept, the one whose rounding to the printed digits
 *     disturbs alpha = -ln(tau)/d least;
 *   - a table longer than LP_GLASS_TABLE_MAX is shortened one point at a
 *     time: while an end lies outside 380-780 nm, the end farther from
 *     that window is dropped (the upper end on a tie); once both ends are
 *     inside it, the interior point that the straight line in ln(tau)
 *     between its neighbours predicts best is dropped (a table of more
 *     than 4 * LP_GLASS_TABLE_MAX points inside the window is first
 *     thinned to that many evenly spread points).
 *
 * Text may be ASCII/UTF-8 (with or without a byte order mark) or UTF-16
 * with a byte order mark; lines may end in LF, CRLF or CR; fields are
 * separated by spaces or tabs.  Numbers are parsed without the C locale,
 * so a program that set LC_NUMERIC to a decimal comma reads them right.
 * Glasses are parsed into a private list and added to the catalog only
 * when the whole text has been read without error.  Text longer than
 * 64 MiB (a file is not read further) and a catalog that would hold more
 * than 20,000 glasses are refused. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "catalog_internal.h"
#include "error.h"

#define MAX_TOKENS 16
#define CD_MAX 10
#define WINDOW_LO_NM 380.0
#define WINDOW_HI_NM 780.0
#define THIN_TO (4 * LP_GLASS_TABLE_MAX)
/* Longest AGF text read (real catalogs are well under 1 MiB; a file is not
 * read past this, so /dev/zero or a runaway file cannot exhaust memory). */
#define AGF_MAX_BYTES ((size_t)64 << 20)
/* Most glasses a catalog may hold (real AGF catalogs have a few hundred;
 * the catalog finds names by a linear search, so this also bounds the
 * time a load and a lookup take). */
#define AGF_MAX_GLASSES 20000

typedef struct token {
    const char *s;
    size_t n;
} token;

typedef struct it_point {
    double lambda_nm;
    double tau;          /* as read */
    double thickness_mm; /* as read */
    double tau_ref;      /* at the reference thickness */
    size_t order;        /* position among the glass's IT lines */
} it_point;

typedef struct parser {
    const char *source; /* names the text in messages */
    unsigned long line;
    lp_error *err;

    lp_glass *list; /* glasses read so far */
    size_t count, capacity;

    /* the glass being read, if `open` */
    int open;
    unsigned long nm_line;
    lp_glass cur;
    double cd[CD_MAX];
    int n_cd;               /* coefficients on the last CD line, -1: none */
    unsigned long cd_line;
    it_point *it;
    size_t n_it, cap_it;
} parser;

/* ---- numbers ------------------------------------------------------------ */

static const double pow10_exact[] = {
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
};

static int is_digit(char c)
{
    return c >= '0' && c <= '9';
}

/* Parse all of s[0..n) as a decimal number ([+-]digits[.digits][e[+-]d]),
 * independent of the locale.  Returns 1 and sets *out, or 0 when s is not
 * such a number or its value is not finite.  With at most 15 significant
 * digits and |exponent| <= 22 (every AGF number) the result is correctly
 * rounded. */
static int parse_number(const char *s, size_t n, double *out)
{
    size_t i = 0;
    uint64_t mant = 0;
    long exp10 = 0;
    int neg = 0, any = 0;
    double v;

    if (i < n && (s[i] == '+' || s[i] == '-'))
        neg = s[i++] == '-';
    for (; i < n && is_digit(s[i]); i++) {
        any = 1;
        if (mant < UINT64_C(100000000000000000))
            mant = mant * 10 + (uint64_t)(s[i] - '0');
        else
            exp10++; /* digits past 17 only scale */
    }
    if (i < n && s[i] == '.') {
        for (i++; i < n && is_digit(s[i]); i++) {
            any = 1;
            if (mant < UINT64_C(100000000000000000)) {
                mant = mant * 10 + (uint64_t)(s[i] - '0');
                exp10--;
            }
        }
    }
    if (!any)
        return 0;
    if (i < n && (s[i] == 'e' || s[i] == 'E')) {
        long e = 0;
        int eneg = 0, edigits = 0;
        i++;
        if (i < n && (s[i] == '+' || s[i] == '-'))
            eneg = s[i++] == '-';
        for (; i < n && is_digit(s[i]); i++) {
            edigits = 1;
            if (e < 100000)
                e = e * 10 + (s[i] - '0');
        }
        if (!edigits)
            return 0;
        exp10 += eneg ? -e : e;
    }
    if (i != n)
        return 0;

    v = (double)mant;
    if (mant == 0)
        v = 0.0;
    else if (mant <= (UINT64_C(1) << 53) && exp10 >= -22 && exp10 <= 22)
        v = exp10 < 0 ? v / pow10_exact[-exp10] : v * pow10_exact[exp10];
    else /* two steps, so that 10^exp10 itself cannot overflow */
        v = v * pow(10.0, (double)(exp10 / 2)) *
            pow(10.0, (double)(exp10 - exp10 / 2));
    if (!isfinite(v))
        return 0;
    *out = neg ? -v : v;
    return 1;
}

/* ---- messages ----------------------------------------------------------- */

static lp_status parse_error(parser *p, unsigned long line, const char *what,
                             const token *t)
{
    if (t)
        return lp__fail(p->err, LP_ERROR_PARSE, "%s, line %lu: %s \"%.*s\"",
                        p->source, line, what, (int)(t->n > 40 ? 40 : t->n),
                        t->s);
    return lp__fail(p->err, LP_ERROR_PARSE, "%s, line %lu: %s", p->source,
                    line, what);
}

static lp_status no_memory(parser *p)
{
    return lp__fail(p->err, LP_ERROR_NO_MEMORY,
                    "%s, line %lu: out of memory", p->source, p->line);
}

/* Parse token t as a number or fail naming `what` (e.g. "CD coefficient"). */
static lp_status number(parser *p, const token *t, const char *what,
                        double *out)
{
    char msg[80];
    if (parse_number(t->s, t->n, out))
        return LP_OK;
    snprintf(msg, sizeof msg, "malformed %s", what);
    return parse_error(p, p->line, msg, t);
}

/* ---- transmittance table ------------------------------------------------ */

/* Order by wavelength, then by order of reading (a stable sort). */
static int by_wavelength(const void *pa, const void *pb)
{
    const it_point *a = pa, *b = pb;
    if (a->lambda_nm != b->lambda_nm)
        return a->lambda_nm < b->lambda_nm ? -1 : 1;
    return (a->order > b->order) - (a->order < b->order);
}

/* How far the point k (interior) lies from the straight line in ln(tau)
 * through its neighbours. */
static double interior_error(const it_point *a, size_t k)
{
    double t = (a[k].lambda_nm - a[k - 1].lambda_nm) /
               (a[k + 1].lambda_nm - a[k - 1].lambda_nm);
    double line = (1.0 - t) * log(a[k - 1].tau_ref) + t * log(a[k + 1].tau_ref);
    return fabs(log(a[k].tau_ref) - line);
}

/* Shorten a sorted table of *n > LP_GLASS_TABLE_MAX points (see the top of
 * the file). */
static void shorten(it_point *a, size_t *n)
{
    size_t lo = 0, hi = *n - 1, i, m;

    /* the ends outside the window, the farther one first */
    while (hi - lo + 1 > LP_GLASS_TABLE_MAX) {
        double below = WINDOW_LO_NM - a[lo].lambda_nm;
        double above = a[hi].lambda_nm - WINDOW_HI_NM;
        if (below <= 0.0 && above <= 0.0)
            break;
        if (below > above)
            lo++;
        else
            hi--;
    }
    m = hi - lo + 1;
    memmove(a, a + lo, m * sizeof *a);

    /* Inside the window: first, for absurdly dense tables, keep
     * THIN_TO evenly spread points (ends included), so that the greedy
     * step below stays cheap. */
    if (m > THIN_TO) {
        for (i = 0; i < THIN_TO; i++)
            a[i] = a[(size_t)((double)i * (double)(m - 1) / (THIN_TO - 1) + 0.5)];
        m = THIN_TO;
    }
    /* then drop the best-predicted interior point, one at a time */
    while (m > LP_GLASS_TABLE_MAX) {
        size_t k, best = 1;
        double best_err = interior_error(a, 1);
        for (k = 2; k + 1 < m; k++) {
            double e = interior_error(a, k);
            if (e < best_err) {
                best_err = e;
                best = k;
            }
        }
        memmove(&a[best], &a[best + 1], (m - best - 1) * sizeof *a);
        m--;
    }
    *n = m;
}

/* Turn the IT readings of the current glass into its table. */
static void build_table(parser *p)
{
    it_point *a = p->it;
    size_t n = p->n_it, i, j;
    double d_ref;

    if (n == 0)
        return;
    d_ref = a[0].thickness_mm;
    for (i = 0; i < n; i++) {
        double tau = a[i].tau > 0.0 ? a[i].tau : LP__TAU_OPAQUE;
        a[i].tau_ref = pow(tau, d_ref / a[i].thickness_mm);
        if (a[i].tau_ref < DBL_MIN) /* extreme thickness ratios */
            a[i].tau_ref = DBL_MIN;
    }
    qsort(a, n, sizeof *a, by_wavelength);

    /* one reading per wavelength: the largest tau * d */
    for (i = 0, j = 0; i < n; i++) {
        if (j > 0 && a[i].lambda_nm == a[j - 1].lambda_nm) {
            if (a[i].tau * a[i].thickness_mm >
                a[j - 1].tau * a[j - 1].thickness_mm)
                a[j - 1] = a[i];
        } else {
            a[j++] = a[i];
        }
    }
    n = j;
    if (n > LP_GLASS_TABLE_MAX)
        shorten(a, &n);

    p->cur.n_tau = (int)n;
    p->cur.tau_thickness_mm = d_ref;
    for (i = 0; i < n; i++) {
        p->cur.tau_lambda_nm[i] = a[i].lambda_nm;
        p->cur.tau[i] = a[i].tau_ref;
    }
}

/* ---- glasses ------------------------------------------------------------ */

/* How many CD values an AGF formula needs (0: not evaluated here). */
static int cd_needed(int agf_formula)
{
    switch (agf_formula) {
    case 1: return 6;
    case 2: return 6;
    case 5: return 3;
    }
    return 0;
}

/* Map the raw CD values into coef[] for the glass's AGF formula. */
static void set_formula(lp_glass *g, const double *cd)
{
    int k;
    switch (g->agf_formula) {
    case 1: /* Schott: a0 a1 a2 a3 a4 a5 */
        g->formula = LP_FORMULA_SCHOTT;
        for (k = 0; k < 6; k++)
            g->coef[k] = cd[k];
        break;
    case 2: /* Sellmeier 1: K1 L1 K2 L2 K3 L3 -> B1 B2 B3 C1 C2 C3 */
        g->formula = LP_FORMULA_SELLMEIER;
        for (k = 0; k < 3; k++) {
            g->coef[k] = cd[2 * k];
            g->coef[3 + k] = cd[2 * k + 1];
        }
        break;
    case 5: /* Conrady: n0 A B */
        g->formula = LP_FORMULA_CONRADY;
        for (k = 0; k < 3; k++)
            g->coef[k] = cd[k];
        break;
    default:
        g->formula = LP_FORMULA_UNSUPPORTED;
        for (k = 0; k < CD_MAX; k++)
            g->coef[k] = cd[k];
        break;
    }
}

/* End the current glass (if any) and append it to the list. */
static lp_status finish_glass(parser *p)
{
    char msg[128];
    if (!p->open)
        return LP_OK;
    if (p->n_cd < 0) {
        snprintf(msg, sizeof msg, "glass \"%s\" has no CD line", p->cur.name);
        return parse_error(p, p->nm_line, msg, NULL);
    }
    if (p->n_cd < cd_needed(p->cur.agf_formula)) {
        snprintf(msg, sizeof msg, "glass \"%s\": AGF formula %d needs %d CD "
                 "coefficients, the CD line has %d", p->cur.name,
                 p->cur.agf_formula, cd_needed(p->cur.agf_formula), p->n_cd);
        return parse_error(p, p->cd_line, msg, NULL);
    }
    set_formula(&p->cur, p->cd);
    build_table(p);
    if (p->count >= AGF_MAX_GLASSES) {
        snprintf(msg, sizeof msg, "more than %d glasses", AGF_MAX_GLASSES);
        return parse_error(p, p->nm_line, msg, NULL);
    }
    if (p->count == p->capacity) {
        size_t cap = p->capacity ? 2 * p->capacity : 32;
        lp_glass *list = realloc(p->list, cap * sizeof *list);
        if (!list)
            return no_memory(p);
        p->list = list;
        p->capacity = cap;
    }
    p->list[p->count++] = p->cur;
    p->open = 0;
    return LP_OK;
}

static lp_status read_nm(parser *p, const token *t, int nt)
{
    double f;
    lp_status s;

    if ((s = finish_glass(p)) != LP_OK)
        return s;
    if (nt < 3)
        return parse_error(p, p->line, "NM line needs a name and a formula "
                                       "number", NULL);
    if (t[1].n >= LP_GLASS_NAME_MAX) {
        char msg[64];
        snprintf(msg, sizeof msg, "glass name longer than %d characters",
                 LP_GLASS_NAME_MAX - 1);
        return parse_error(p, p->line, msg, &t[1]);
    }
    if (!parse_number(t[2].s, t[2].n, &f) || f != floor(f) ||
        fabs(f) > 1000.0)
        return parse_error(p, p->line, "malformed formula number", &t[2]);

    memset(&p->cur, 0, sizeof p->cur);
    memcpy(p->cur.name, t[1].s, t[1].n);
    p->cur.agf_formula = (int)f;
    memset(p->cd, 0, sizeof p->cd);
    p->n_cd = -1;
    p->n_it = 0;
    p->open = 1;
    p->nm_line = p->line;
    return LP_OK;
}

static lp_status need_glass(parser *p, const token *keyword)
{
    if (p->open)
        return LP_OK;
    return parse_error(p, p->line, "data line before any NM line:", keyword);
}

static lp_status read_cd(parser *p, const token *t, int nt)
{
    int k;
    lp_status s;
    if ((s = need_glass(p, &t[0])) != LP_OK)
        return s;
    memset(p->cd, 0, sizeof p->cd);
    for (k = 1; k < nt && k <= CD_MAX; k++)
        if ((s = number(p, &t[k], "CD coefficient", &p->cd[k - 1])) != LP_OK)
            return s;
    p->n_cd = k - 1;
    p->cd_line = p->line;
    return LP_OK;
}

static lp_status read_ld(parser *p, const token *t, int nt)
{
    double lo, hi;
    lp_status s;
    if ((s = need_glass(p, &t[0])) != LP_OK)
        return s;
    if (nt < 3)
        return parse_error(p, p->line, "LD line needs two wavelengths", NULL);
    if ((s = number(p, &t[1], "LD wavelength", &lo)) != LP_OK ||
        (s = number(p, &t[2], "LD wavelength", &hi)) != LP_OK)
        return s;
    if (!(lo == 0.0 && hi == 0.0) && !(lo >= 0.0 && lo < hi))
        return parse_error(p, p->line, "LD range is not 0 <= min < max", NULL);
    if (!isfinite(hi * 1e3))
        return parse_error(p, p->line, "LD wavelength out of range", &t[2]);
    p->cur.lambda_min_nm = lo * 1e3;
    p->cur.lambda_max_nm = hi * 1e3;
    return LP_OK;
}

static lp_status read_it(parser *p, const token *t, int nt)
{
    it_point x;
    lp_status s;
    if ((s = need_glass(p, &t[0])) != LP_OK)
        return s;
    if (nt < 4)
        return parse_error(p, p->line, "IT line needs a wavelength, a "
                                       "transmittance and a thickness", NULL);
    if ((s = number(p, &t[1], "IT wavelength", &x.lambda_nm)) != LP_OK ||
        (s = number(p, &t[2], "IT transmittance", &x.tau)) != LP_OK ||
        (s = number(p, &t[3], "IT thickness", &x.thickness_mm)) != LP_OK)
        return s;
    if (!(x.lambda_nm > 0.0) || !isfinite(x.lambda_nm * 1e3))
        return parse_error(p, p->line, "IT wavelength is not > 0 (or out of range)",
                           &t[1]);
    if (!(x.tau >= 0.0 && x.tau <= 1.0))
        return parse_error(p, p->line, "IT transmittance is not in [0, 1]",
                           &t[2]);
    if (!(x.thickness_mm > 0.0))
        return parse_error(p, p->line, "IT thickness is not > 0", &t[3]);
    x.lambda_nm *= 1e3;
    x.tau_ref = x.tau;
    x.order = p->n_it;
    if (p->n_it == p->cap_it) {
        size_t cap = p->cap_it ? 2 * p->cap_it : 64;
        it_point *it = realloc(p->it, cap * sizeof *it);
        if (!it)
            return no_memory(p);
        p->it = it;
        p->cap_it = cap;
    }
    p->it[p->n_it++] = x;
    return LP_OK;
}

/* ---- lines -------------------------------------------------------------- */

static int is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\v' || c == '\f';
}

/* Split s[0..n) into at most MAX_TOKENS tokens; returns how many. */
static int tokenize(const char *s, size_t n, token *t)
{
    size_t i = 0;
    int nt = 0;
    while (nt < MAX_TOKENS) {
        while (i < n && is_blank(s[i]))
            i++;
        if (i == n)
            break;
        t[nt].s = s + i;
        while (i < n && !is_blank(s[i]))
            i++;
        t[nt].n = i - (size_t)(t[nt].s - s);
        nt++;
    }
    return nt;
}

static char upper(char c)
{
    return c >= 'a' && c <= 'z' ? (char)(c - 'a' + 'A') : c;
}

/* 1 when t is the two-letter record type kw (upper case), in any case. */
static int keyword_is(const token *t, const char *kw)
{
    return t->n == 2 && upper(t->s[0]) == kw[0] && upper(t->s[1]) == kw[1];
}

static lp_status read_line(parser *p, const char *s, size_t n)
{
    token t[MAX_TOKENS];
    int nt = tokenize(s, n, t);
    if (nt == 0)
        return LP_OK;
    if (keyword_is(&t[0], "NM"))
        return read_nm(p, t, nt);
    if (keyword_is(&t[0], "CD"))
        return read_cd(p, t, nt);
    if (keyword_is(&t[0], "LD"))
        return read_ld(p, t, nt);
    if (keyword_is(&t[0], "IT"))
        return read_it(p, t, nt);
    return LP_OK; /* CC GC ED TD OD BD and anything unknown */
}

static lp_status read_text(parser *p, const char *text, size_t len)
{
    size_t i = 0;
    lp_status s;
    while (i < len) {
        size_t start = i;
        while (i < len && text[i] != '\n' && text[i] != '\r')
            i++;
        p->line++;
        if ((s = read_line(p, text + start, i - start)) != LP_OK)
            return s;
        if (i + 1 < len && text[i] == '\r' && text[i + 1] == '\n')
            i += 2; /* CRLF */
        else if (i < len)
            i++; /* LF or CR */
    }
    return finish_glass(p);
}

/* ---- encodings ---------------------------------------------------------- */

static size_t put_utf8(char *o, uint32_t cp)
{
    if (cp < 0x80) {
        o[0] = (char)cp;
        return 1;
    }
    if (cp < 0x800) {
        o[0] = (char)(0xC0 | (cp >> 6));
        o[1] = (char)(0x80 | (cp & 0x3F));
        return 2;
    }
    if (cp < 0x10000) {
        o[0] = (char)(0xE0 | (cp >> 12));
        o[1] = (char)(0x80 | ((cp >> 6) & 0x3F));
        o[2] = (char)(0x80 | (cp & 0x3F));
        return 3;
    }
    o[0] = (char)(0xF0 | (cp >> 18));
    o[1] = (char)(0x80 | ((cp >> 12) & 0x3F));
    o[2] = (char)(0x80 | ((cp >> 6) & 0x3F));
    o[3] = (char)(0x80 | (cp & 0x3F));
    return 4;
}

/* Decode UTF-16 (big_endian or little) into a new UTF-8 buffer. */
static lp_status utf16_to_utf8(parser *p, const unsigned char *in, size_t n,
                               int big_endian, char **out, size_t *out_len)
{
    size_t units = n / 2, i, len = 0;
    char *o;
    if (n % 2)
        return lp__fail(p->err, LP_ERROR_PARSE,
                        "%s: UTF-16 text has an odd number of bytes", p->source);
    o = malloc(units * 3 + 1); /* a unit never takes more than 3 bytes */
    if (!o)
        return lp__fail(p->err, LP_ERROR_NO_MEMORY, "%s: out of memory",
                        p->source);
    for (i = 0; i < units; i++) {
        uint32_t u = big_endian ? (uint32_t)in[2 * i] << 8 | in[2 * i + 1]
                                : (uint32_t)in[2 * i + 1] << 8 | in[2 * i];
        if (u >= 0xD800 && u <= 0xDBFF && i + 1 < units) {
            uint32_t v = big_endian
                ? (uint32_t)in[2 * i + 2] << 8 | in[2 * i + 3]
                : (uint32_t)in[2 * i + 3] << 8 | in[2 * i + 2];
            if (v >= 0xDC00 && v <= 0xDFFF) {
                u = 0x10000 + ((u - 0xD800) << 10) + (v - 0xDC00);
                i++;
            } else {
                u = 0xFFFD;
            }
        } else if (u >= 0xD800 && u <= 0xDFFF) {
            u = 0xFFFD; /* a lone surrogate */
        }
        len += put_utf8(o + len, u);
    }
    o[len] = '\0';
    *out = o;
    *out_len = len;
    return LP_OK;
}

/* Parse bytes[0..n) and, if all is well, add its glasses to the catalog. */
static lp_status load(lp_catalog *catalog, const unsigned char *bytes,
                      size_t n, const char *source, lp_error *err)
{
    parser p;
    char *decoded = NULL;
    const char *text = (const char *)bytes;
    size_t len = n;
    lp_status s;

    memset(&p, 0, sizeof p);
    p.source = source;
    p.err = err;

    if (n > AGF_MAX_BYTES)
        return lp__fail(err, LP_ERROR_PARSE, "%s: larger than %u MiB",
                        source, (unsigned)(AGF_MAX_BYTES >> 20));

    if (n >= 2 && bytes[0] == 0xFF && bytes[1] == 0xFE)
        s = utf16_to_utf8(&p, bytes + 2, n - 2, 0, &decoded, &len);
    else if (n >= 2 && bytes[0] == 0xFE && bytes[1] == 0xFF)
        s = utf16_to_utf8(&p, bytes + 2, n - 2, 1, &decoded, &len);
    else
        s = LP_OK;
    if (s != LP_OK)
        return s;
    if (decoded) {
        text = decoded;
    } else if (n >= 3 && bytes[0] == 0xEF && bytes[1] == 0xBB &&
               bytes[2] == 0xBF) {
        text += 3;
        len -= 3;
    }

    if (memchr(text, '\0', len))
        s = lp__fail(err, LP_ERROR_PARSE,
                     "%s: text contains NUL bytes (UTF-16 needs a byte order "
                     "mark)", source);
    else
        s = read_text(&p, text, len);
    if (s == LP_OK && (lp_catalog_count(catalog) > AGF_MAX_GLASSES ||
                       p.count > AGF_MAX_GLASSES - lp_catalog_count(catalog)))
        s = lp__fail(err, LP_ERROR_PARSE,
                     "%s: the catalog would hold more than %d glasses", source,
                     AGF_MAX_GLASSES);
    if (s == LP_OK)
        s = lp__catalog_add(catalog, p.list, p.count, err);
    if (s == LP_OK)
        lp__ok(err);

    free(decoded);
    free(p.list);
    free(p.it);
    return s;
}

lp_status lp_catalog_load_agf_text(lp_catalog *catalog, const char *text,
                                   size_t len, lp_error *err)
{
    if (!catalog)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                        "lp_catalog_load_agf_text: catalog is NULL");
    if (!text && len > 0)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                        "lp_catalog_load_agf_text: text is NULL");
    return load(catalog, (const unsigned char *)(text ? text : ""), len,
                "AGF text", err);
}

lp_status lp_catalog_load_agf(lp_catalog *catalog, const char *path,
                              lp_error *err)
{
    unsigned char *buf = NULL;
    size_t len = 0, cap = 0;
    FILE *f;
    lp_status s;

    if (!catalog || !path)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT,
                        "lp_catalog_load_agf: %s is NULL",
                        catalog ? "path" : "catalog");
    f = fopen(path, "rb");
    if (!f)
        return lp__fail(err, LP_ERROR_IO, "cannot open AGF file \"%s\"", path);
    for (;;) {
        size_t got;
        if (len == cap) {
            size_t ncap = cap ? 2 * cap : 65536;
            unsigned char *nbuf;
            if (ncap > AGF_MAX_BYTES + 1)
                ncap = AGF_MAX_BYTES + 1; /* one byte more tells "too long" */
            nbuf = realloc(buf, ncap);
            if (!nbuf) {
                free(buf);
                fclose(f);
                return lp__fail(err, LP_ERROR_NO_MEMORY,
                                "out of memory reading \"%s\"", path);
            }
            buf = nbuf;
            cap = ncap;
        }
        got = fread(buf + len, 1, cap - len, f);
        len += got;
        if (got == 0 || len > AGF_MAX_BYTES)
            break; /* len > MAX: too long, refused by load() */
    }
    if (ferror(f)) {
        free(buf);
        fclose(f);
        return lp__fail(err, LP_ERROR_IO, "error reading AGF file \"%s\"", path);
    }
    fclose(f);
    s = load(catalog, buf, len, path, err);
    free(buf);
    return s;
}
