/*
 * spherecontact_table.c -- C99 evaluator of a spherecontact contact table, format v2.
 * The rule implemented here is dem/FORMAT.md, section by section.
 */
#include "spherecontact_table.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NCOL 13 /* node row: ln_h lnF dF_l dF_r lna da_l da_r phi dp_l dp_r recovery m h1_res */

typedef struct {
    double ratio, R1, R2, Rs, log_Rs, h_elastic, h_min, h_max;
    int n;
    double *s;                 /* nodes ln h */
    double *rec, *m, *h1r;     /* unloading parameters at the nodes */
    double end[2][7];          /* first / last node: s, lnF, dlnF, lna, dlna, phi, (unused) */
    double *rows;              /* the node rows as read (n x NCOL) */
    /* per interval j, one 64-byte line each (BLK doubles), so that a force needs one line: */
    double *blkF;              /* s_j, s_j+1, 1/(s_j+1 - s_j), 4 Hermite coefficients of ln F */
    double *blkA;              /* 4 Hermite coefficients of ln a, 4 of phi */
    double *blkU;              /* recovery, its increment, m, its increment, h1_res, its increment */
    double *blk_mem;           /* the allocation holding the three */
    int ng;                    /* lookup grid: ng bins of equal width in ln h over the nodes, */
    int *grid;                 /* grid[b] = last node j <= n - 2 with s[j] <= the bin's start */
    double g0, ginv;           /* s of the first node, bins per unit of ln h */
} sct_slice;

struct sct_table {
    int S;
    sct_slice *sl;
    double *x;    /* ln ratio of the slices */
    double *wden; /* 1 / prod_{b != a} (x_a - x_b) of stencil i0's slice a: wden[i0 * SCT_ORDER + a] */
    char *meta;
};

static void set_err(char *err, size_t len, const char *fmt, ...) {
    if (!err || !len) return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, len, fmt, ap);
    va_end(ap);
}

static double r_star(double R1, double R2) { return isinf(R2) ? R1 : R1 * R2 / (R1 + R2); }

/* ------------------------------------------------------------------ loading */

static char *read_all(const char *path, char *err, size_t errlen) {
    FILE *f = fopen(path, "rb");
    if (!f) {
        set_err(err, errlen, "cannot open contact table '%s': %s", path, strerror(errno));
        return NULL;
    }
    size_t cap = 1 << 16, len = 0;
    char *buf = malloc(cap);
    while (buf) {
        size_t got = fread(buf + len, 1, cap - len - 1, f);
        len += got;
        if (len < cap - 1) break;
        char *nb = realloc(buf, cap * 2);
        if (!nb) { free(buf); buf = NULL; break; }
        buf = nb;
        cap *= 2;
    }
    fclose(f);
    if (!buf) { set_err(err, errlen, "contact table '%s': out of memory", path); return NULL; }
    buf[len] = '\0';
    return buf;
}

/* next line of the buffer (NUL-terminated in place), NULL at the end */
static char *next_line(char **cur) {
    char *p = *cur;
    if (!p || !*p) return NULL;
    char *e = strchr(p, '\n');
    if (e) { *e = '\0'; *cur = e + 1; } else { *cur = p + strlen(p); }
    size_t l = strlen(p);
    if (l && p[l - 1] == '\r') p[l - 1] = '\0';
    return p;
}

static int parse_doubles(const char *line, double *out, int want) {
    const char *p = line;
    for (int i = 0; i < want; i++) {
        char *e;
        out[i] = strtod(p, &e);
        if (e == p) return i;
        p = e;
    }
    while (*p == ' ' || *p == '\t') p++;
    return *p ? -1 : want; /* trailing garbage */
}

static void hermite(const double *y0, const double *y1, double d0, double d1, double ds,
                    double *c) {
    double m0 = d0 * ds, m1 = d1 * ds;
    c[0] = *y0;
    c[1] = m0;
    c[2] = 3.0 * (*y1 - *y0) - 2.0 * m0 - m1;
    c[3] = 2.0 * (*y0 - *y1) + m0 + m1;
}

#define BLK 8 /* doubles per interval block: one 64-byte cache line */

/* the three block arrays of a slice in one allocation, aligned to 64 bytes (C99: by hand) */
static int alloc_blocks(sct_slice *q) {
    size_t len = (size_t)BLK * (size_t)(q->n - 1);
    q->blk_mem = calloc(3 * len + 8, sizeof(double));
    if (!q->blk_mem) return 0;
    uintptr_t p = ((uintptr_t)q->blk_mem + 63) & ~(uintptr_t)63;
    q->blkF = (double *)p;
    q->blkA = q->blkF + len;
    q->blkU = q->blkA + len;
    return 1;
}

static int build_slice(sct_slice *q, char *err, size_t errlen, const char *path, int i) {
    int n = q->n;
    double *r = q->rows;
    q->s = malloc(sizeof(double) * n);
    q->rec = malloc(sizeof(double) * n);
    q->m = malloc(sizeof(double) * n);
    q->h1r = malloc(sizeof(double) * n);
    if (!q->s || !q->rec || !q->m || !q->h1r || !alloc_blocks(q)) {
        set_err(err, errlen, "contact table '%s': out of memory", path);
        return SCT_ERR_IO;
    }
    for (int j = 0; j < n; j++) {
        const double *row = r + (size_t)j * NCOL;
        for (int c = 0; c < NCOL; c++)
            if (isnan(row[c])) {
                set_err(err, errlen, "contact table '%s' is corrupt: slice %d node %d column %d is NaN",
                        path, i, j, c + 1);
                return SCT_ERR_FORMAT;
            }
        q->s[j] = row[0];
        q->rec[j] = row[10];
        q->m[j] = row[11];
        q->h1r[j] = row[12];
        if (j > 0 && !(row[0] > r[(size_t)(j - 1) * NCOL])) {
            set_err(err, errlen, "contact table '%s' is corrupt: slice %d nodes ln_h not increasing at "
                    "node %d", path, i, j);
            return SCT_ERR_FORMAT;
        }
    }
    for (int j = 0; j + 1 < n; j++) {
        const double *a = r + (size_t)j * NCOL, *b = a + NCOL;
        double ds = b[0] - a[0];
        double *F = q->blkF + (size_t)BLK * j, *A = q->blkA + (size_t)BLK * j;
        double *U = q->blkU + (size_t)BLK * j;
        F[0] = a[0];
        F[1] = b[0];
        F[2] = 1.0 / ds;
        hermite(&a[1], &b[1], a[3], b[2], ds, F + 3);
        hermite(&a[4], &b[4], a[6], b[5], ds, A);
        hermite(&a[7], &b[7], a[9], b[8], ds, A + 4);
        U[0] = a[10];
        U[1] = b[10] - a[10];
        U[2] = a[11];
        U[3] = b[11] - a[11];
        U[4] = a[12];
        U[5] = b[12] - a[12];
    }
    const double *f = r, *l = r + (size_t)(n - 1) * NCOL;
    double e0[7] = {f[0], f[1], f[3], f[4], f[6], f[7], 0.0};
    double e1[7] = {l[0], l[1], l[2], l[4], l[5], l[7], 0.0};
    memcpy(q->end[0], e0, sizeof e0);
    memcpy(q->end[1], e1, sizeof e1);
    q->Rs = r_star(q->R1, q->R2);
    q->log_Rs = log(q->Rs);
    /* interval lookup in O(1): 4 bins per node on average, then a short forward scan */
    q->ng = n >= 2 ? 4 * n : 0;
    q->grid = NULL;
    if (q->ng) {
        q->grid = malloc(sizeof(int) * q->ng);
        if (!q->grid) {
            set_err(err, errlen, "contact table '%s': out of memory", path);
            return SCT_ERR_IO;
        }
        q->g0 = q->s[0];
        q->ginv = q->ng / (q->s[n - 1] - q->s[0]);
        int j = 0;
        for (int b = 0; b < q->ng; b++) {
            double sb = q->g0 + b / q->ginv;
            while (j < n - 2 && q->s[j + 1] <= sb) j++;
            q->grid[b] = j;
        }
    }
    return SCT_OK;
}

void sct_free(sct_table *t) {
    if (!t) return;
    for (int i = 0; i < t->S; i++) {
        sct_slice *q = &t->sl[i];
        free(q->s); free(q->rec); free(q->m); free(q->h1r); free(q->rows); free(q->grid);
        free(q->blk_mem);
    }
    free(t->sl);
    free(t->x);
    free(t->wden);
    free(t->meta);
    free(t);
}

/* value of "key" in "... key VALUE ..." of a slice header */
static int header_value(const char *line, const char *key, double *v) {
    size_t kl = strlen(key);
    const char *p = line;
    while ((p = strstr(p, key)) != NULL) {
        if ((p == line || p[-1] == ' ') && p[kl] == ' ') {
            char *e;
            *v = strtod(p + kl + 1, &e);
            return e != p + kl + 1;
        }
        p += kl;
    }
    return 0;
}

sct_table *sct_load(const char *path, char *err, size_t errlen) {
    char *buf = read_all(path, err, errlen);
    if (!buf) return NULL;
    sct_table *t = calloc(1, sizeof *t);
    char *cur = buf, *line;
    int nread = 0, lineno = 1, ended = 0;
    if (!t) goto oom;
    line = next_line(&cur);
    if (!line || strcmp(line, SCT_FORMAT) != 0) {
        set_err(err, errlen, "'%s' is not a contact table of format %s (first line '%.40s')", path,
                SCT_FORMAT, line ? line : "");
        goto fail;
    }
    t->S = -1;
    while ((line = next_line(&cur)) != NULL) {
        lineno++;
        if (line[0] == '#' || line[0] == '\0') continue;
        if (strncmp(line, "meta ", 5) == 0) {
            free(t->meta);
            t->meta = malloc(strlen(line + 5) + 1);
            if (!t->meta) goto oom;
            strcpy(t->meta, line + 5);
        } else if (strncmp(line, "slices ", 7) == 0) {
            t->S = atoi(line + 7);
            if (t->S < 1 || t->sl) {
                set_err(err, errlen, "contact table '%s' is corrupt: line %d '%.40s'", path, lineno, line);
                goto fail;
            }
            t->sl = calloc((size_t)t->S, sizeof(sct_slice));
            t->x = calloc((size_t)t->S, sizeof(double));
            if (!t->sl || !t->x) goto oom;
        } else if (strncmp(line, "slice ", 6) == 0) {
            if (!t->sl || nread >= t->S) {
                set_err(err, errlen, "contact table '%s' is corrupt: slice before 'slices' or more "
                        "slices than declared (line %d)", path, lineno);
                goto fail;
            }
            sct_slice *q = &t->sl[nread];
            double nn;
            if (!header_value(line, "ratio", &q->ratio) || !header_value(line, "R1", &q->R1) ||
                !header_value(line, "R2", &q->R2) || !header_value(line, "nodes", &nn) ||
                !header_value(line, "h_elastic", &q->h_elastic) ||
                !header_value(line, "h_min", &q->h_min) || !header_value(line, "h_max", &q->h_max) ||
                nn < 2 || !(q->R1 > 0) || !(q->R2 > 0) || !(q->ratio > 0)) {
                set_err(err, errlen, "contact table '%s' is corrupt: bad slice header at line %d", path,
                        lineno);
                goto fail;
            }
            q->n = (int)nn;
            q->rows = malloc(sizeof(double) * NCOL * (size_t)q->n);
            if (!q->rows) goto oom;
            for (int j = 0; j < q->n; j++) {
                line = next_line(&cur);
                lineno++;
                if (!line || parse_doubles(line, q->rows + (size_t)j * NCOL, NCOL) != NCOL) {
                    set_err(err, errlen, "contact table '%s' is corrupt: slice %d node row %d (line %d) "
                            "needs %d numbers", path, nread, j, lineno, NCOL);
                    goto fail;
                }
            }
            int rc = build_slice(q, err, errlen, path, nread);
            if (rc != SCT_OK) goto fail;
            t->x[nread] = log(q->ratio);
            if (nread > 0 && !(t->x[nread] > t->x[nread - 1])) {
                set_err(err, errlen, "contact table '%s' is corrupt: slice ratios not increasing", path);
                goto fail;
            }
            nread++;
        } else if (strncmp(line, "check ", 6) == 0) {
            continue;
        } else if (strcmp(line, "end") == 0) {
            ended = 1;
            break;
        } else {
            set_err(err, errlen, "contact table '%s' is corrupt: unknown record at line %d '%.40s'", path,
                    lineno, line);
            goto fail;
        }
    }
    if (t->S < 1 || nread != t->S || !ended) {
        set_err(err, errlen, "contact table '%s' is corrupt or truncated: %d of %d slices read%s", path,
                nread, t->S < 0 ? 0 : t->S, ended ? "" : ", no 'end' line");
        goto fail;
    }
    if (t->S > 1 && isinf(t->sl[t->S - 1].ratio)) {
        set_err(err, errlen, "contact table '%s' is corrupt: a flat (ratio inf) in a ratio range", path);
        goto fail;
    }
    if (t->S > 1) { /* Lagrange denominators of every stencil (FORMAT.md, contact step 1) */
        int k = t->S < SCT_ORDER ? t->S : SCT_ORDER;
        t->wden = calloc((size_t)t->S * SCT_ORDER, sizeof(double));
        if (!t->wden) goto oom;
        for (int i0 = 0; i0 + k <= t->S; i0++)
            for (int a = 0; a < k; a++) {
                double d = 1.0;
                for (int b = 0; b < k; b++)
                    if (b != a) d *= t->x[i0 + a] - t->x[i0 + b];
                t->wden[i0 * SCT_ORDER + a] = 1.0 / d;
            }
    }
    if (!t->meta) {
        t->meta = calloc(1, 1);
        if (!t->meta) goto oom;
    }
    free(buf);
    return t;
oom:
    set_err(err, errlen, "contact table '%s': out of memory", path);
fail:
    free(buf);
    if (t && t->S < 0) t->S = 0;
    if (t && !t->sl) t->S = 0;
    sct_free(t);
    return NULL;
}

/* ------------------------------------------------------------------ evaluation */

int sct_stencil_for(const sct_table *t, double R1, double R2, sct_stencil *st, char *err,
                    size_t errlen) {
    if (!(R1 > 0.0) || isinf(R1) || !(R2 > 0.0)) {
        set_err(err, errlen, "radii must be > 0 (R2 may be inf: a flat), got R1 = %g, R2 = %g", R1, R2);
        return SCT_ERR_ARG;
    }
    double ratio = isinf(R2) ? INFINITY : R2 / R1;
    double lo = t->sl[0].ratio, hi = t->sl[t->S - 1].ratio;
    double Rs = r_star(R1, R2);
    if (t->S == 1 || isinf(ratio) || isinf(hi)) {
        int ok = (ratio == lo) || (!isinf(ratio) && !isinf(lo) &&
                                   fabs(log(ratio / lo)) <= SCT_RATIO_TOLERANCE);
        if (!ok) goto outside;
        st->n = 1;
        st->idx[0] = 0;
        st->w[0] = 1.0;
        st->lam[0] = Rs / t->sl[0].Rs;
        st->Rs = Rs;
        st->h_elastic = t->sl[0].h_elastic * st->lam[0];
        return SCT_OK;
    }
    double x = log(ratio);
    if (!(x >= t->x[0] - SCT_RATIO_TOLERANCE && x <= t->x[t->S - 1] + SCT_RATIO_TOLERANCE))
        goto outside;
    if (x < t->x[0]) x = t->x[0];
    if (x > t->x[t->S - 1]) x = t->x[t->S - 1];
    int k = t->S < SCT_ORDER ? t->S : SCT_ORDER;
    int j = 0;
    while (j < t->S - 2 && x >= t->x[j + 1]) j++;
    int i0 = j - k / 2 + 1;
    if (i0 > t->S - k) i0 = t->S - k;
    if (i0 < 0) i0 = 0;
    st->n = k;
    st->Rs = Rs;
    double d[SCT_ORDER];
    for (int a = 0; a < k; a++) d[a] = x - t->x[i0 + a];
    for (int a = 0; a < k; a++) {
        double w = t->wden[i0 * SCT_ORDER + a];
        for (int b = 0; b < k; b++)
            if (b != a) w *= d[b];
        st->idx[a] = i0 + a;
        st->w[a] = w;
        st->lam[a] = Rs / t->sl[i0 + a].Rs;
        double he = t->sl[i0 + a].h_elastic * st->lam[a];
        if (a == 0 || he < st->h_elastic) st->h_elastic = he;
    }
    return SCT_OK;
outside:
    set_err(err, errlen, "radius ratio R2/R1 = %.10g (R1 = %g, R2 = %g) is outside the contact table's "
            "range [%.10g, %.10g]", ratio, R1, R2, lo, hi);
    return SCT_ERR_RATIO;
}

/* parts of a slice's values (FORMAT.md, one slice): v = ln F, g, ln a, phi, recovery, m, h1_res */
#define PART_A 1      /* ln a */
#define PART_PHI 2    /* phi */
#define PART_UNLOAD 4 /* recovery, m */
#define PART_H1RES 8  /* h1_res */

/* the end node's rule beyond the table (s below the first node or above the last) */
static void slice_beyond(const sct_slice *q, double s, int parts, double *v) {
    int e = s > q->end[1][0];
    const double *E = q->end[e];
    int node = e ? q->n - 1 : 0;
    double ds = s - E[0];
    v[0] = E[1] + E[2] * ds;
    v[1] = E[2];
    if (parts & PART_A) v[2] = E[3] + E[4] * ds;
    if (parts & PART_PHI) v[3] = E[5];
    if (parts & PART_UNLOAD) {
        v[4] = q->rec[node];
        v[5] = q->m[node];
    }
    if (parts & PART_H1RES) v[6] = q->h1r[node];
}

/* the interval j (0 ... n-2) of s inside the table, s_j <= s < s_j+1 (s_n-1 itself: the last):
   from the grid's node j_b one step either way without a branch (a bin rarely holds two node
   boundaries, then the scan) */
static inline int interval_of(const sct_slice *q, double s, int jb) {
    const double *F = q->blkF + (size_t)BLK * jb;
    int j = jb + (s >= F[1]) - (s < F[0]);
    if (j > q->n - 2) j = q->n - 2;
    F = q->blkF + (size_t)BLK * j;
    if (F[0] <= s && (s < F[1] || j == q->n - 2)) return j;
    while (j > 0 && F[0] > s) { j--; F -= BLK; }
    while (j < q->n - 2 && F[1] <= s) { j++; F += BLK; }
    return j;
}

/* the slice's values in interval j at s (FORMAT.md, one slice, step 1) */
static inline void slice_in(const sct_slice *q, int j, double s, int parts, double *v) {
    const double *F = q->blkF + (size_t)BLK * j;
    double inv = F[2];
    double t = (s - F[0]) * inv;
    const double *c = F + 3;
    v[0] = ((c[3] * t + c[2]) * t + c[1]) * t + c[0];
    v[1] = ((c[3] * (3.0 * t) + 2.0 * c[2]) * t + c[1]) * inv;
    if (parts & (PART_A | PART_PHI)) {
        const double *A = q->blkA + (size_t)BLK * j;
        if (parts & PART_A) v[2] = A[0] + t * (A[1] + t * (A[2] + t * A[3]));
        if (parts & PART_PHI) v[3] = A[4] + t * (A[5] + t * (A[6] + t * A[7]));
    }
    if (parts & (PART_UNLOAD | PART_H1RES)) {
        const double *U = q->blkU + (size_t)BLK * j;
        if (parts & PART_UNLOAD) {
            v[4] = U[0] + t * U[1];
            v[5] = U[2] + t * U[3];
        }
        if (parts & PART_H1RES) v[6] = U[4] + t * U[5];
    }
}

void sct_eval_parts(const sct_table *t, const sct_stencil *st, double h, double h_max, int want,
                    sct_result *out) {
    int loading = (h >= h_max) || (h_max <= st->h_elastic);
    double q = loading ? h : h_max;
    out->F = out->dF_dh = out->a = out->h1 = 0.0;
    if (!(q > 0.0)) return;
    int parts = ((want & SCT_WANT_A) ? PART_A : 0) | ((want & SCT_WANT_H1) ? PART_PHI : 0);
    if (!loading) parts |= PART_UNLOAD | ((want & SCT_WANT_H1) ? PART_H1RES : 0);
    double acc[7] = {0, 0, 0, 0, 0, 0, 0}, v[7] = {0, 0, 0, 0, 0, 0, 0};
    /* slice i at q / lambda_i, lambda_i = R* / R*_i: s_i = ln(q / R*) + ln R*_i; one logarithm */
    double lq = log(q / st->Rs);
    /* the slices' lookups first, one pass each, so that their memory loads overlap */
    const sct_slice *sl[SCT_ORDER];
    double si[SCT_ORDER];
    int ji[SCT_ORDER];
    for (int i = 0; i < st->n; i++) {
        const sct_slice *q = sl[i] = &t->sl[st->idx[i]];
        si[i] = lq + q->log_Rs;
        ji[i] = -1; /* beyond the table */
        if (si[i] >= q->end[0][0] && si[i] <= q->end[1][0]) {
            int b = (int)((si[i] - q->g0) * q->ginv);
            b = b < 0 ? 0 : (b >= q->ng ? q->ng - 1 : b);
            ji[i] = q->grid[b];
        }
    }
    for (int i = 0; i < st->n; i++)
        if (ji[i] >= 0) ji[i] = interval_of(sl[i], si[i], ji[i]);
    for (int i = 0; i < st->n; i++) {
        if (ji[i] >= 0)
            slice_in(sl[i], ji[i], si[i], parts, v);
        else
            slice_beyond(sl[i], si[i], parts, v);
        double w = st->w[i];
        /* ln F = sum w_i (ln F_i + 2 ln lambda_i) = 2 ln R* + sum w_i (ln F_i - 2 ln R*_i), as
           the weights sum to 1; ln a likewise with ln R* */
        acc[0] += w * (v[0] - 2.0 * sl[i]->log_Rs);
        acc[1] += w * v[1];
        acc[2] += w * (v[2] - sl[i]->log_Rs);
        for (int c = 3; c < 7; c++) acc[c] += w * v[c];
    }
    double Fq = st->Rs * st->Rs * exp(acc[0]);
    double aq = (want & SCT_WANT_A) ? st->Rs * exp(acc[2]) : 0.0;
    if (loading) {
        out->F = Fq;
        out->dF_dh = Fq * acc[1] / q;
        out->a = aq;
        out->h1 = acc[3] * q;
        return;
    }
    double delta = acc[4] * q, m = acc[5];
    double xi = (h - q) / delta + 1.0;
    if (xi > 1.0) xi = 1.0;
    if (!(xi > 0.0)) return; /* separated */
    double xm1 = exp((m - 1.0) * log(xi));
    out->F = Fq * xi * xm1;
    out->dF_dh = m * Fq * xm1 / delta;
    out->a = aq * xm1;
    double h1res = acc[6] * q;
    out->h1 = h1res + xi * (acc[3] * q - h1res);
}

void sct_eval_stencil(const sct_table *t, const sct_stencil *st, double h, double h_max,
                      sct_result *out) {
    sct_eval_parts(t, st, h, h_max, SCT_WANT_ALL, out);
}

int sct_eval(const sct_table *t, double R1, double R2, double h, double h_max, sct_result *out) {
    sct_stencil st;
    int rc = sct_stencil_for(t, R1, R2, &st, NULL, 0);
    if (rc != SCT_OK) return rc;
    sct_eval_stencil(t, &st, h, h_max, out);
    return SCT_OK;
}

int sct_eval_many(const sct_table *t, double R1, double R2, size_t n, const double *h,
                  const double *h_max, double *F, double *dF_dh, double *a, double *h1) {
    sct_stencil st;
    int rc = sct_stencil_for(t, R1, R2, &st, NULL, 0);
    if (rc != SCT_OK) return rc;
    for (size_t i = 0; i < n; i++) {
        sct_result r;
        sct_eval_stencil(t, &st, h[i], h_max[i], &r);
        if (F) F[i] = r.F;
        if (dF_dh) dF_dh[i] = r.dF_dh;
        if (a) a[i] = r.a;
        if (h1) h1[i] = r.h1;
    }
    return SCT_OK;
}

void sct_ratio_range(const sct_table *t, double *lo, double *hi) {
    *lo = t->sl[0].ratio;
    *hi = t->sl[t->S - 1].ratio;
}

int sct_slices(const sct_table *t) { return t->S; }

const char *sct_meta(const sct_table *t) { return t->meta; }

double sct_h_max(const sct_table *t, const sct_stencil *st) {
    double hm = INFINITY;
    for (int i = 0; i < st->n; i++) {
        double v = t->sl[st->idx[i]].h_max * st->lam[i];
        if (v < hm) hm = v;
    }
    return hm;
}

double sct_max_stiffness(const sct_table *t, const sct_stencil *st, double h_cap) {
    /* loading stiffness and the unloading stiffness at the peak (xi = 1: m F/delta_e) at every
       node of the stencil's first slice up to h_cap, and at h_cap itself */
    const sct_slice *q = &t->sl[st->idx[0]];
    double kmax = 0.0;
    sct_result r;
    for (int j = 0; j <= q->n; j++) {
        double hp = j < q->n ? exp(q->s[j]) * st->lam[0] : h_cap;
        if (hp > h_cap) hp = h_cap;
        sct_eval_stencil(t, st, hp, hp, &r);
        if (r.dF_dh > kmax) kmax = r.dF_dh;
        sct_eval_stencil(t, st, hp * (1.0 - 1e-12), hp, &r);
        if (r.dF_dh > kmax) kmax = r.dF_dh;
        if (hp >= h_cap) break;
    }
    return kmax;
}
