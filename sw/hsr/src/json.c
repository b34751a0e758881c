/* json.c - --dump-llr writer: every visible (LLR) domain with its MLR id,
 * parents, rings and plane, in pixel coordinates (schema: docs/hsr.md). */
#include <stdio.h>
#include <stdlib.h>
#include "internal.h"

hsr_status hsr_write_llr_json(const char *path, const hsr_ctx *h, const hsr_scene *sc)
{
    if (!path || !h || !sc) return HSR_EINVAL;
    FILE *f = fopen(path, "w");
    if (!f) return HSR_EIO;
    const double S = HSR_SUBPIXEL;
    hsr_status st = HSR_OK;
    fprintf(f, "{\"format\": \"hsr-llr-1\", \"units_per_pixel\": %d, \"width\": %d, \"height\": %d,\n"
               " \"mlr_count\": %d, \"domains\": [", HSR_SUBPIXEL, sc->width, sc->height, hsr_mlr_slots(h));
    int first = 1;
    for (int s = 0; s < hsr_llr_slots(h) && st == HSR_OK; s++) {
        const hsr_domain *d; const int *par; int nv, np;
        if (!hsr_llr_get(h, s, &d, &par, &nv, &np)) continue;
        hsr_plane pl = {0, 0, 0};
        hsr_mlr_get(h, par[0], NULL, &pl, NULL, NULL, NULL);
        double *xy; int *len, nr;
        st = hsr_domain_rings(d, &xy, &len, &nr);
        if (st != HSR_OK) break;
        fprintf(f, "%s\n  {\"mlr\": %d, \"parents\": [", first ? "" : ",", par[0]);
        first = 0;
        for (int i = 0; i < nv; i++) fprintf(f, "%s%d", i ? ", " : "", par[i]);
        fprintf(f, "], \"hidden_parents\": [");
        for (int i = nv; i < np; i++) fprintf(f, "%s%d", i > nv ? ", " : "", par[i]);
        fprintf(f, "], \"area_px2\": %.17g, \"plane\": [%.17g, %.17g, %.17g],\n   \"rings\": [",
                hsr_domain_area(d) / (S * S), pl.a * S, pl.b * S, pl.c);
        for (int r = 0, off = 0; r < nr; off += len[r], r++) {
            fprintf(f, "%s[", r ? ", " : "");
            for (int i = 0; i < len[r]; i++)
                fprintf(f, "%s[%.17g, %.17g]", i ? ", " : "", xy[2 * (off + i)] / S, xy[2 * (off + i) + 1] / S);
            fprintf(f, "]");
        }
        fprintf(f, "]}");
        free(xy); free(len);
    }
    fprintf(f, "\n]}\n");
    if (fclose(f) != 0 && st == HSR_OK) st = HSR_EIO;
    return st;
}
