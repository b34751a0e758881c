/* yp_cover.c - exact per-pixel coverage of a domain (section 5.5, eq. 5.6).
 * Each directed boundary segment adds, per pixel row it crosses, the
 * signed area between itself and the right end of the row, split over the
 * pixels it passes (the accumulation scheme of font rasterisers); the
 * running sum along a row is then the covered area of each pixel.  For
 * straight segments this is exact up to double rounding (about 1e-13 of
 * a pixel), so the pieces of one pixel shared by several domains sum to
 * its area. */
#include <math.h>
#include "yp_internal.h"

static void segment(double x0, double y0, double x1, double y1, double *acc, int nx, int ny)
{
    if (y0 == y1) return;
    double dir = 1;
    if (y0 > y1) { double t = x0; x0 = x1; x1 = t; t = y0; y0 = y1; y1 = t; dir = -1; }
    const int stride = nx + 2;
    double dxdy = (x1 - x0) / (y1 - y0), x = x0;
    int ya = (int)floor(y0), yb = (int)ceil(y1);
    if (ya < 0) { x -= y0 * dxdy; ya = 0; y0 = 0; }   /* not expected: buffer covers the domain */
    if (yb > ny) yb = ny;
    for (int y = ya; y < yb; y++) {
        double *row = acc + (size_t)y * stride;
        double dy = fmin((double)(y + 1), y1) - fmax((double)y, y0);
        /* the row's last x: exactly x1 at the segment's end, which stepping would miss
         * by a rounding error, below 0 if x1 = 0 (a vertex on the box's left side) */
        double xn = y + 1 >= y1 ? x1 : x + dxdy * dy, d = dy * dir;
        /* the box holds the domain, so x < 0 is a rounding error: take 0 (clamping only
         * the pixel index would leave xm > 1 below and the wrong sign in cell 0) */
        double xa = fmax(0, x < xn ? x : xn), xb = fmax(0, x < xn ? xn : x);
        double xaf = floor(xa), xbc = ceil(xb);
        int ia = (int)xaf, ib = (int)xbc;
        if (ib > nx + 1) ib = nx + 1;
        if (ib <= ia + 1) {
            double xm = 0.5 * (xa + xb) - xaf;
            row[ia] += d - d * xm;
            if (ia + 1 < stride) row[ia + 1] += d * xm;
        } else {
            double s = 1.0 / (xb - xa), f0 = xa - xaf;
            double a0 = 0.5 * s * (1 - f0) * (1 - f0);
            double f1 = xb - xbc + 1;
            double am = 0.5 * s * f1 * f1;
            row[ia] += d * a0;
            if (ib == ia + 2) row[ia + 1] += d * (1 - a0 - am);
            else {
                double a1 = s * (1.5 - f0);
                row[ia + 1] += d * (a1 - a0);
                for (int i = ia + 2; i < ib - 1; i++) row[i] += d * s;
                double a2 = a1 + (ib - ia - 3) * s;
                row[ib - 1] += d * (1 - a2 - am);
            }
            if (ib < stride) row[ib] += d * am;
        }
        x = xn;
    }
}

void yp_cover_ring(const double *xy, int n, double *acc, int nx, int ny)
{
    for (int i = 0; i < n; i++) {
        int j = (i + 1) % n;
        segment(xy[2 * i], xy[2 * i + 1], xy[2 * j], xy[2 * j + 1], acc, nx, ny);
    }
}
