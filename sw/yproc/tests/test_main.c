/* test_main.c - runs every suite of sw/yproc; prints "N passed, M failed" last. */
#include <string.h>
#include "t.h"

void suite_yp_tex_lod(void);   /* test_yp_tex_lod.c */
void suite_yp_coh(void);       /* test_yp_coh.c */
void suite_yp_tess(void);      /* test_yp_tess.c */
void suite_yp_fmodel(void);    /* test_yp_fmodel.c */

int main(int argc, char **argv)
{
    for (int i = 1; i < argc; i++)
        if (!strcmp(argv[i], "--quick")) t_quick = 1;
    suite_yp();
    suite_obj_shading();
    suite_yp_tex_lod();
    suite_yp_coh();
    suite_yp_tess();
    suite_yp_fmodel();
    return t_report();
}
