/* yproc_tools.h - what the files of the yproc command share (tools/; not a library
 * header: the library's is include/yproc.h). */
#ifndef YPROC_TOOLS_H
#define YPROC_TOOLS_H

#include <time.h>
#include "yproc.h"

int yproc_scan_main(int argc, char **argv);    /* yproc_scan.c */
int yproc_serve_main(int argc, char **argv);   /* yproc_serve.c */
int yproc_apply_ops(hsr_ctx *h, const char *path, double **shade);   /* yproc_ops.c */
/* yproc.c: the usage on stderr after "yproc: WHAT 'ARG'" (what may be NULL); returns 2 */
int yproc_usage_error(const char *what, const char *arg);
/* yproc.c: milliseconds on clock id (CLOCK_PROCESS_CPUTIME_ID: the scan's figures on a
 * shared machine; CLOCK_MONOTONIC: the viewer's latency) */
double yproc_clock_ms(clockid_t id);

#endif
