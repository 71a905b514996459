/* sa_point.c -- the table of measured settings (see sa_point.h). */
#include "sa_point.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void sa_point_init(sa_point *p, const char *kind, const char *model, int wavelengths,
                   int depth, double cutoff)
{
    memset(p, 0, sizeof *p);
    snprintf(p->kind, sizeof p->kind, "%.15s", kind);
    snprintf(p->model, sizeof p->model, "%.15s", model);
    p->wavelengths = wavelengths;
    p->depth = depth;
    p->cutoff = cutoff;
    p->seconds = NAN;
    p->err.rmse = p->err.max_abs = p->err.share_visible = NAN;
}

void sa_points_init(sa_points *ps)
{
    memset(ps, 0, sizeof *ps);
}

void sa_points_free(sa_points *ps)
{
    free(ps->p);
    sa_points_init(ps);
}

int sa_points_add(sa_points *ps, const sa_point *p)
{
    if (ps->n == ps->cap) {
        size_t cap = ps->cap ? 2 * ps->cap : 256;
        sa_point *q = realloc(ps->p, cap * sizeof *q);
        if (!q)
            return -1;
        ps->p = q;
        ps->cap = cap;
    }
    ps->p[ps->n++] = *p;
    return 0;
}

int sa_point_write_csv_header(FILE *f)
{
    return fputs("scene,kind,model,wavelengths,depth,cutoff,tolerance,seconds,runs,rmse,max_abs,"
                 "share_visible,note\n", f) < 0 ? -1 : 0;
}

int sa_point_write_csv(FILE *f, const sa_point *p)
{
    char note[sizeof p->note];
    size_t k;
    for (k = 0; p->note[k] && k + 1 < sizeof note; k++)
        note[k] = (p->note[k] == ',' || p->note[k] == '"' || p->note[k] == '\n') ? ';' : p->note[k];
    note[k] = '\0';
    return fprintf(f, "%s,%s,%s,%d,%d,%.6g,%.6g,%.6g,%d,%.6g,%.6g,%.6g,%s\n", p->scene, p->kind,
                   p->model, p->wavelengths, p->depth, p->cutoff, p->tolerance, p->seconds,
                   p->runs, p->err.rmse, p->err.max_abs, p->err.share_visible, note) < 0 ? -1 : 0;
}

/* Copy field k of a comma-separated line into out. */
static const char *field(const char *s, char *out, size_t size)
{
    size_t n = strcspn(s, ",\n");
    snprintf(out, size, "%.*s", (int)n, s);
    return s[n] == ',' ? s + n + 1 : s + n;
}

int sa_points_read_csv(const char *path, sa_points *ps, char *msg, size_t msg_size)
{
    FILE *f = fopen(path, "r");
    char line[2048], v[13][512];
    int ln = 0;
    if (!f) {
        snprintf(msg, msg_size, "cannot open");
        return -1;
    }
    while (fgets(line, sizeof line, f)) {
        const char *s = line;
        sa_point p;
        if (++ln == 1)
            continue;
        for (int k = 0; k < 13; k++)
            s = field(s, v[k], sizeof v[k]);
        sa_point_init(&p, v[1], v[2], atoi(v[3]), atoi(v[4]), strtod(v[5], NULL));
        snprintf(p.scene, sizeof p.scene, "%.63s", v[0]);
        p.tolerance = strtod(v[6], NULL);
        p.seconds = strtod(v[7], NULL);
        p.runs = atoi(v[8]);
        p.err.rmse = strtod(v[9], NULL);
        p.err.max_abs = strtod(v[10], NULL);
        p.err.share_visible = strtod(v[11], NULL);
        snprintf(p.note, sizeof p.note, "%s", v[12]);
        if (p.scene[0] == '\0' || p.kind[0] == '\0') {
            snprintf(msg, msg_size, "line %d: no scene or kind", ln);
            fclose(f);
            return -1;
        }
        if (sa_points_add(ps, &p) != 0) {
            snprintf(msg, msg_size, "out of memory");
            fclose(f);
            return -1;
        }
    }
    fclose(f);
    return 0;
}
