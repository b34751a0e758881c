/* test_main.c - runs every suite of sw/yproc; prints "N passed, M failed" last. */
#include <string.h>
#include "t.h"

int main(int argc, char **argv)
{
    for (int i = 1; i < argc; i++)
        if (!strcmp(argv[i], "--quick")) t_quick = 1;
    suite_yp();
    suite_obj_shading();
    return t_report();
}
