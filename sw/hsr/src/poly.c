/* poly.c - how an OBJ polygon becomes triangles.  The faces it makes are what
 * `yproc read` hands the Python reference renderer (the project's one reader;
 * docs/hsr.md, "Polygons" and "hsr-scene-1"). */
#include <math.h>
#include "internal.h"

#define PLANAR_TOL 1e-6     /* relative to the bounding box diagonal */

typedef struct proj { const double *p; int i, j; double sign; } proj;

/* twice the signed area of (a, b, c) in the projection, > 0 counter-
 * clockwise seen from the side the Newell normal points to */
static double cross2(const proj *q, int a, int b, int c)
{
    const double *A = &q->p[3 * a], *B = &q->p[3 * b], *C = &q->p[3 * c];
    return q->sign * ((B[q->i] - A[q->i]) * (C[q->j] - A[q->j]) - (B[q->j] - A[q->j]) * (C[q->i] - A[q->i]));
}

static int convex(const proj *q, int n)
{
    for (int k = 0; k < n; k++)
        if (cross2(q, (k + n - 1) % n, k, (k + 1) % n) < 0) return 0;
    for (int k = 1; k + 1 < n; k++)
        if (cross2(q, 0, k, k + 1) < 0 || cross2(q, 0, 1, k + 1) < 0) return 0;
    return 1;
}

int poly_triangulate(const double *p, int n, int *tri, int *whole)
{
    double N[3] = {0, 0, 0}, lo[3], hi[3], c[3] = {0, 0, 0};
    for (int k = 0; k < 3; k++) { lo[k] = p[k]; hi[k] = p[k]; }
    for (int a = 0; a < n; a++) {
        const double *P = &p[3 * a], *R = &p[3 * ((a + 1) % n)];
        N[0] += (P[1] - R[1]) * (P[2] + R[2]);
        N[1] += (P[2] - R[2]) * (P[0] + R[0]);
        N[2] += (P[0] - R[0]) * (P[1] + R[1]);
        for (int k = 0; k < 3; k++) {
            c[k] += P[k];
            lo[k] = fmin(lo[k], P[k]); hi[k] = fmax(hi[k], P[k]);
        }
    }
    int ax = 0;
    if (fabs(N[1]) > fabs(N[ax])) ax = 1;
    if (fabs(N[2]) > fabs(N[ax])) ax = 2;
    proj q = {p, (ax + 1) % 3, (ax + 2) % 3, N[ax] >= 0 ? 1.0 : -1.0};
    int cv = convex(&q, n);
    double len = sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
    double diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1])
                       + (hi[2] - lo[2]) * (hi[2] - lo[2]));
    double dev = 0;
    if (len > 0)
        for (int a = 0; a < n; a++) {
            double d = 0;
            for (int k = 0; k < 3; k++) d += (p[3 * a + k] - c[k] / n) * (N[k] / len);
            dev = fmax(dev, fabs(d));
        }
    *whole = n == 3 || (cv && len > 0 && dev <= PLANAR_TOL * diag);
    int nt = 0;
    if (!cv) {
        /* ear clipping: repeatedly cut the first ear (a convex corner whose triangle
         * holds no other remaining point, boundary included) in polygon order */
        int idx[512], m = n;
        if (n > 512) m = 0;                 /* cannot happen (512 items per OBJ line) */
        for (int k = 0; k < m; k++) idx[k] = k;
        while (m > 3) {
            int found = -1;
            for (int k = 0; k < m && found < 0; k++) {
                int a = idx[(k + m - 1) % m], b = idx[k], cc = idx[(k + 1) % m];
                if (!(cross2(&q, a, b, cc) > 0)) continue;
                int ok = 1;
                for (int r = 0; r < m && ok; r++) {
                    int t = idx[r];
                    if (t == a || t == b || t == cc) continue;
                    if (cross2(&q, a, b, t) >= 0 && cross2(&q, b, cc, t) >= 0 && cross2(&q, cc, a, t) >= 0) ok = 0;
                }
                if (ok) found = k;
            }
            if (found < 0) break;           /* self-intersecting or degenerate: fan the rest */
            tri[3 * nt] = idx[(found + m - 1) % m]; tri[3 * nt + 1] = idx[found];
            tri[3 * nt + 2] = idx[(found + 1) % m]; nt++;
            for (int k = found; k + 1 < m; k++) idx[k] = idx[k + 1];
            m--;
        }
        for (int k = 1; k + 1 < m; k++) {
            tri[3 * nt] = idx[0]; tri[3 * nt + 1] = idx[k]; tri[3 * nt + 2] = idx[k + 1]; nt++;
        }
        if (nt == n - 2) return nt;
        nt = 0;                             /* n > 512: plain fan */
    }
    for (int k = 1; k + 1 < n; k++) { tri[3 * nt] = 0; tri[3 * nt + 1] = k; tri[3 * nt + 2] = k + 1; nt++; }
    return nt;
}
