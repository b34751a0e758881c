/* fuzz_obj.c - the OBJ parser, then projection + HSR of whatever parsed.
 * Invariants: a status, never a crash; an error names "f.obj:<line>" (or,
 * for an `mtllib` file, that file's "path:<line>"); a scene that parses
 * builds a visibility map that passes hsr_check, and a y-processor shader. */
#include <string.h>
#include "yproc.h"
#include "fuzz.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 4096) return 0;                 /* keep one run fast */
    char *text = fuzz_cstr(data, size);
    hsr_scene *sc = NULL;
    char err[256] = "";
    if (!text || hsr_scene_new(&sc) != HSR_OK) { free(text); hsr_scene_free(sc); return 0; }
    hsr_status st = hsr_obj_parse(sc, text, "f.obj", 0, err, sizeof err);
    if (st != HSR_OK) {
        FUZZ_ASSERT(st != HSR_ENOMEM ? strncmp(err, "f.obj:", 6) == 0 || (sc->nfiles > 0 && strchr(err, ':')) : 1);
    } else {
        sc->width = 64; sc->height = 48;
        hsr_ctx *h = NULL;
        double *shade = NULL;
        if (hsr_scene_build(sc, &h, &shade) == HSR_OK) FUZZ_ASSERT(hsr_check(h) == HSR_OK);
        /* corner normals (vn, smoothing groups, triangulated polygons): a status, and
         * a shader whenever the no-wrap check passes */
        yp_shader *sh = NULL;
        char err2[512] = "";
        hsr_status s2 = yp_shader_new(sc, YP_PHONG, &sh, err2, sizeof err2);
        FUZZ_ASSERT(s2 == HSR_OK ? sh != NULL : s2 == HSR_EPARSE || s2 == HSR_ENOMEM || s2 == HSR_EINVAL);
        yp_shader_free(sh);
        free(shade);
        hsr_destroy(h);
    }
    hsr_scene_free(sc);
    free(text);
    return 0;
}
