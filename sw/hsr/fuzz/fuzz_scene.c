/* fuzz_scene.c - the scene-file parser (camera, lights, materials, obj lines).
 * Invariant: a status, never a crash; an error names "f.scene:<line>". */
#include <string.h>
#include "hsr.h"
#include "fuzz.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 4096) return 0;
    char *text = fuzz_cstr(data, size);
    hsr_scene *sc = NULL;
    char err[256] = "";
    if (!text || hsr_scene_new(&sc) != HSR_OK) { free(text); hsr_scene_free(sc); return 0; }
    /* "/nonexistent": an obj line must fail with a file error, not read the disk. */
    hsr_status st = hsr_scene_parse(sc, text, "f.scene", "/nonexistent", err, sizeof err);
    if (st != HSR_OK && st != HSR_ENOMEM) FUZZ_ASSERT(strncmp(err, "f.scene:", 8) == 0);
    hsr_scene_free(sc);
    free(text);
    return 0;
}
