/* yproc_ops.c - `yproc hsr SCENE --ops FILE`: after the scene is built, apply a
 * sequence of incremental operations to the MLR / LLR (docs/hsr.md, "Operation
 * file").  One operation a line, '#' starts a comment:
 *
 *   remove ID            hsr_remove
 *   move ID DX DY        hsr_move: translate MLR domain ID by (DX, DY) pixels
 *                        (rounded to 1/256 px); its depth plane moves with it
 *   add ID DX DY         hsr_add: a copy of MLR domain ID (present, or as it was
 *                        when removed) translated by (DX, DY); gets the next id
 *   opacity ID A         hsr_set_opacity, A in [0, 1]
 *
 * IDs are MLR ids (face index in reading order, then the adds in order),
 * 0 <= ID < number of MLR domains so far.  Every error (malformed line,
 * non-finite number, id out of range or removed, coordinates beyond
 * +-HSR_COORD_MAX after the move, a failing library call) is printed as
 * "file:line: message" and nothing after it is applied. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "yproc_tools.h"

typedef struct saved { hsr_domain *dom; hsr_plane pl; double op; } saved;

static int parse_int(const char *s, long *out)
{
    char *end;
    if (!s) return 0;
    long v = strtol(s, &end, 10);
    if (end == s || *end) return 0;
    *out = v;
    return 1;
}

static int parse_num(const char *s, double *out)
{
    char *end;
    if (!s) return 0;
    double v = strtod(s, &end);
    if (end == s || *end || !isfinite(v)) return 0;
    *out = v;
    return 1;
}

/* Rings of dom translated by (dx, dy) units, as integer units. */
static hsr_status translated(const hsr_domain *dom, int64_t dx, int64_t dy,
                             int64_t **xy_out, int **len_out, int *nr_out)
{
    double *xy; int *len, nr;
    hsr_status st = hsr_domain_rings(dom, &xy, &len, &nr);
    if (st != HSR_OK) return st;
    int tot = 0;
    for (int r = 0; r < nr; r++) tot += len[r];
    int64_t *q = malloc(sizeof(int64_t) * 2 * (size_t)(tot + 1));
    if (!q) { free(xy); free(len); return HSR_ENOMEM; }
    for (int i = 0; i < tot && st == HSR_OK; i++) {
        double x = nearbyint(xy[2 * i]) + (double)dx, y = nearbyint(xy[2 * i + 1]) + (double)dy;
        if (fabs(x) > (double)HSR_COORD_MAX || fabs(y) > (double)HSR_COORD_MAX) st = HSR_ERANGE;
        else { q[2 * i] = (int64_t)x; q[2 * i + 1] = (int64_t)y; }
    }
    free(xy);
    if (st != HSR_OK) { free(q); free(len); return st; }
    *xy_out = q; *len_out = len; *nr_out = nr;
    return HSR_OK;
}

/* The translation in units; |D| <= 2 * HSR_COORD_MAX px keeps it far from overflow. */
static int units(double px, int64_t *u)
{
    if (!(fabs(px) <= 2.0 * (double)HSR_COORD_MAX / HSR_SUBPIXEL)) return 0;
    *u = (int64_t)nearbyint(px * HSR_SUBPIXEL);
    return 1;
}

static hsr_status do_line(hsr_ctx *h, char *line, saved **sv, int *nsv, double **shade,
                          char *msg, size_t msglen)
{
    char *tok[6];
    int nt = 0;
    for (char *t = strtok(line, " \t\r\n"); t && nt < 6; t = strtok(NULL, " \t\r\n")) tok[nt++] = t;
    if (nt == 0) return HSR_OK;
    const char *op = tok[0];
    int want = !strcmp(op, "remove") ? 2 : !strcmp(op, "opacity") ? 3
             : (!strcmp(op, "move") || !strcmp(op, "add")) ? 4 : 0;
    if (!want) { snprintf(msg, msglen, "unknown operation '%s' (remove, move, add, opacity)", op); return HSR_EPARSE; }
    if (nt != want) { snprintf(msg, msglen, "'%s' takes %d arguments", op, want - 1); return HSR_EPARSE; }
    long id;
    int nm = hsr_mlr_slots(h);
    if (!parse_int(tok[1], &id)) { snprintf(msg, msglen, "bad id '%s'", tok[1]); return HSR_EPARSE; }
    if (id < 0 || id >= nm) { snprintf(msg, msglen, "id %ld out of range 0..%d", id, nm - 1); return HSR_EPARSE; }
    const hsr_domain *dom; hsr_plane pl; double opac;
    int present = hsr_mlr_get(h, (int)id, &dom, &pl, &opac, NULL, NULL);
    if (!present && strcmp(op, "add")) { snprintf(msg, msglen, "MLR domain %ld was removed", id); return HSR_EPARSE; }
    hsr_status st;
    if (!strcmp(op, "opacity")) {
        double a;
        if (!parse_num(tok[2], &a) || a < 0 || a > 1) { snprintf(msg, msglen, "opacity must be a number in [0, 1]"); return HSR_EPARSE; }
        st = hsr_set_opacity(h, (int)id, a);
    } else if (!strcmp(op, "remove")) {
        if (*nsv < nm) {   /* keep a copy for a later "add ID" */
            saved *q = realloc(*sv, sizeof(saved) * (size_t)nm);
            if (!q) return HSR_ENOMEM;
            memset(q + *nsv, 0, sizeof(saved) * (size_t)(nm - *nsv));
            *sv = q; *nsv = nm;
        }
        saved *s = &(*sv)[id];
        hsr_domain_free(s->dom);
        s->dom = hsr_domain_clone(dom); s->pl = pl; s->op = opac;
        if (!s->dom) return HSR_ENOMEM;
        st = hsr_remove(h, (int)id);
    } else {
        double dxp, dyp;
        int64_t dx, dy;
        if (!parse_num(tok[2], &dxp) || !parse_num(tok[3], &dyp) || !units(dxp, &dx) || !units(dyp, &dy)) {
            snprintf(msg, msglen, "bad translation '%s %s' (finite pixels)", tok[2], tok[3]);
            return HSR_EPARSE;
        }
        if (!present) {
            if (id >= *nsv || !(*sv)[id].dom) { snprintf(msg, msglen, "MLR domain %ld has no geometry", id); return HSR_EPARSE; }
            dom = (*sv)[id].dom; pl = (*sv)[id].pl; opac = (*sv)[id].op;
        }
        int64_t *xy; int *len, nr;
        st = translated(dom, dx, dy, &xy, &len, &nr);
        if (st == HSR_ERANGE) { snprintf(msg, msglen, "translated coordinates beyond +-%.4f px", (double)HSR_COORD_MAX / HSR_SUBPIXEL); return st; }
        if (st != HSR_OK) return st;
        /* z(x, y) of the moved copy = z(x - dx, y - dy) of the original */
        pl.c -= pl.a * (double)dx + pl.b * (double)dy;
        if (!strcmp(op, "move")) st = hsr_move(h, (int)id, xy, len, nr, pl);
        else {   /* the copy is drawn (--svg) in the colour of its source */
            double *q = realloc(*shade, sizeof(double) * 4 * (size_t)(nm + 1));
            if (q) { *shade = q; memcpy(q + 4 * nm, q + 4 * id, sizeof(double) * 4); }
            st = q ? hsr_add(h, xy, len, nr, pl, opac, NULL) : HSR_ENOMEM;
        }
        free(xy); free(len);
    }
    if (st != HSR_OK) snprintf(msg, msglen, "%s %ld: %s", op, id, hsr_status_str(st));
    return st;
}

/* Returns 0, or 1 after printing "file:line: message".  shade: 4 doubles per
 * MLR id (hsr_scene_build), extended for every add. */
int yproc_apply_ops(hsr_ctx *h, const char *path, double **shade)
{
    FILE *f = fopen(path, "r");
    if (!f) { fprintf(stderr, "%s:0: cannot open\n", path); return 1; }
    saved *sv = NULL;
    int nsv = 0, lineno = 0, rc = 0;
    char line[4096], msg[256];
    while (fgets(line, sizeof line, f)) {
        lineno++;
        size_t n = strlen(line);
        if (n == sizeof line - 1 && line[n - 1] != '\n' && !feof(f)) {
            fprintf(stderr, "%s:%d: line longer than %d characters\n", path, lineno, (int)sizeof line - 2);
            rc = 1; break;
        }
        char *hash = strchr(line, '#');
        if (hash) *hash = 0;
        msg[0] = 0;
        if (do_line(h, line, &sv, &nsv, shade, msg, sizeof msg) != HSR_OK) {
            fprintf(stderr, "%s:%d: %s\n", path, lineno, msg[0] ? msg : "out of memory");
            rc = 1; break;
        }
    }
    if (!rc && ferror(f)) { fprintf(stderr, "%s:%d: read error\n", path, lineno); rc = 1; }
    fclose(f);
    for (int i = 0; i < nsv; i++) hsr_domain_free(sv[i].dom);
    free(sv);
    return rc;
}
