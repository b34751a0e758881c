/* svg.c - the visibility map as SVG: one even-odd path per LLR domain,
 * coloured by compositing its ordered parents front to back over the
 * background (transparent parents mix, section 5.4.1). */
#include <stdio.h>
#include <stdlib.h>
#include "internal.h"

static int byte(double v) { v = v < 0 ? 0 : (v > 1 ? 1 : v); return (int)(v * 255 + 0.5); }

hsr_status hsr_write_svg(const char *path, const hsr_ctx *h, const hsr_scene *sc, const double *shade)
{
    if (!path || !h || !sc || !shade) return HSR_EINVAL;
    FILE *f = fopen(path, "w");
    if (!f) return HSR_EIO;
    const double S = HSR_SUBPIXEL;
    hsr_status st = HSR_OK;
    fprintf(f, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\">\n"
               "<rect width=\"%d\" height=\"%d\" fill=\"#%02x%02x%02x\"/>\n", sc->width, sc->height,
            sc->width, sc->height, sc->width, sc->height, byte(sc->bg[0]), byte(sc->bg[1]), byte(sc->bg[2]));
    for (int s = 0; s < hsr_llr_slots(h) && st == HSR_OK; s++) {
        const hsr_domain *d; const int *par; int nv, np;
        if (!hsr_llr_get(h, s, &d, &par, &nv, &np)) continue;
        double c[3] = {0, 0, 0}, t = 1;
        for (int i = 0; i < nv; i++) {
            const double *sh = &shade[4 * par[i]];
            for (int k = 0; k < 3; k++) c[k] += t * sh[3] * sh[k];
            t *= 1 - sh[3];
        }
        for (int k = 0; k < 3; k++) c[k] += t * sc->bg[k];
        double *xy; int *len, nr;
        st = hsr_domain_rings(d, &xy, &len, &nr);
        if (st != HSR_OK) break;
        fprintf(f, "<path data-mlr=\"%d\" fill=\"#%02x%02x%02x\" fill-rule=\"evenodd\" d=\"", par[0],
                byte(c[0]), byte(c[1]), byte(c[2]));
        for (int r = 0, off = 0; r < nr; off += len[r], r++) {
            for (int i = 0; i < len[r]; i++)
                fprintf(f, "%s%.4f %.4f ", i ? "L" : "M", xy[2 * (off + i)] / S, xy[2 * (off + i) + 1] / S);
            fprintf(f, "Z");
        }
        fprintf(f, "\"/>\n");
        free(xy); free(len);
    }
    fprintf(f, "</svg>\n");
    if (fclose(f) != 0 && st == HSR_OK) st = HSR_EIO;
    return st;
}
