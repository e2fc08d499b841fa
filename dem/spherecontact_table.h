/*
 * spherecontact_table.h -- C99 evaluator of a spherecontact contact table, format v2
 * ("spherecontact-contact-table/2", specification: dem/FORMAT.md).
 *
 * Dependencies: the C standard library and libm. Thread safety: a loaded table is read-only;
 * any number of threads may evaluate it at once.
 *
 *   char err[256];
 *   sct_table *t = sct_load("steel_alu.sct", err, sizeof err);
 *   if (!t) { fprintf(stderr, "%s\n", err); ... }
 *   sct_stencil st;                       // once per pair of radii (e.g. per contact)
 *   if (sct_stencil_for(t, R1, R2, &st, err, sizeof err) != SCT_OK) { ... ratio outside ... }
 *   sct_result r;
 *   sct_eval_stencil(t, &st, h, h_max, &r);   // r.F, r.dF_dh, r.a, r.h1
 *   h_max = h > h_max ? h : h_max;            // the history is the caller's
 *   sct_free(t);
 */
#ifndef SPHERECONTACT_TABLE_H
#define SPHERECONTACT_TABLE_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SCT_FORMAT "spherecontact-contact-table/2"

/* return codes */
#define SCT_OK 0
#define SCT_ERR_IO 1      /* file missing or unreadable */
#define SCT_ERR_FORMAT 2  /* not a v2 table, or a corrupt one */
#define SCT_ERR_RATIO 3   /* radius ratio R2/R1 outside the table's range */
#define SCT_ERR_ARG 4     /* bad argument (radius <= 0, NaN, ...) */

/* a contact's ratio may lie this far outside the table's range in ln(R2/R1) (then clamped) */
#define SCT_RATIO_TOLERANCE 1e-6
/* slices of the Lagrange stencil in ln(R2/R1) */
#define SCT_ORDER 4

typedef struct sct_table sct_table;

/* F: normal force; dF_dh: its derivative along the current branch; a: contact radius;
   h1: body 1's share of the approach h (h - h1 is body 2's). All 0 without contact. */
typedef struct {
    double F, dF_dh, a, h1;
} sct_result;

/* The slices and weights for one pair of radii (sct_stencil_for). */
typedef struct {
    int n;                    /* slices used, 1 ... SCT_ORDER */
    int idx[SCT_ORDER];       /* their indices */
    double w[SCT_ORDER];      /* Lagrange weights in ln(R2/R1) */
    double lam[SCT_ORDER];    /* size factors R* / R*_i */
    double Rs;                /* the contact's R* = R1 R2 / (R1 + R2) (R1 on a flat) */
    double h_elastic;         /* a peak up to here is elastic: min over the slices of lam_i He_i */
} sct_stencil;

/* Load a table; NULL on failure with the reason (naming the file and the problem) in err. */
sct_table *sct_load(const char *path, char *err, size_t errlen);
void sct_free(sct_table *t);

/* The stencil of a contact of radii R1 (body 1) and R2 (body 2; INFINITY: a flat).
   SCT_ERR_RATIO (message naming the ratio and the range) if R2/R1 is outside the table. */
int sct_stencil_for(const sct_table *t, double R1, double R2, sct_stencil *st, char *err,
                    size_t errlen);

/* Evaluate the law at approach h with history h_max (the largest approach reached before). */
void sct_eval_stencil(const sct_table *t, const sct_stencil *st, double h, double h_max,
                      sct_result *out);

/* The same, computing only the parts a caller needs: F and dF/dh always, a with SCT_WANT_A, h1
   with SCT_WANT_H1 (a part not asked for is 0 in out). */
#define SCT_WANT_A 1
#define SCT_WANT_H1 2
#define SCT_WANT_ALL (SCT_WANT_A | SCT_WANT_H1)
void sct_eval_parts(const sct_table *t, const sct_stencil *st, double h, double h_max, int want,
                    sct_result *out);

/* Both steps for one contact; returns SCT_OK or SCT_ERR_RATIO / SCT_ERR_ARG. */
int sct_eval(const sct_table *t, double R1, double R2, double h, double h_max, sct_result *out);

/* n contacts of the same radii (arrays of length n; any output pointer may be NULL). */
int sct_eval_many(const sct_table *t, double R1, double R2, size_t n, const double *h,
                  const double *h_max, double *F, double *dF_dh, double *a, double *h1);

/* The table's ratio range [lo, hi] (lo == hi for a one-slice table; INFINITY for a wall). */
void sct_ratio_range(const sct_table *t, double *lo, double *hi);
int sct_slices(const sct_table *t);
/* The largest approach tabulated for the stencil's contact size (smallest over its slices). */
double sct_h_max(const sct_table *t, const sct_stencil *st);
/* The largest stiffness dF/dh of the contact for peaks up to h_cap, on loading and unloading
   (for a critical time step estimate; sampled at the table's nodes). */
double sct_max_stiffness(const sct_table *t, const sct_stencil *st, double h_cap);
/* The meta JSON line (informative), "" if none. */
const char *sct_meta(const sct_table *t);

#ifdef __cplusplus
}
#endif
#endif
