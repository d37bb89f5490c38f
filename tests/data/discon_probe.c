/* A Bladed-style test controller for tests/mpc_wt/controllers/test_discon.py: it appends every record it
 * receives (1..130) to <OUTNAME>.swap.csv (and, where the array holds them, OpenFAST's lidar
 * records 2001-2016 to <OUTNAME>.lidar.csv), counts its calls in a global (one count per loaded
 * copy), answers fixed demands, and stops the run (aviFAIL = -1) at t >= 0.5 s when its input
 * file is named PROBE_STOP.IN; with PROBE_EXIT.IN it prints a line and calls exit(3) there, with
 * PROBE_CRASH.IN it prints a line and writes through a null pointer (a segfault); with
 * PROBE_HANG.IN it blocks for good there, with PROBE_SPIN.IN it loops for good. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int calls = 0;

void DISCON(float *swap, int *fail, const char *infile, char *outname, char *msg)
{
    char path[4200];
    FILE *f;
    int k;
    calls++;
    snprintf(path, sizeof path, "%s.swap.csv", outname);
    f = fopen(path, "a");
    if (f) {
        fprintf(f, "%d", calls);
        for (k = 0; k < 130; k++) fprintf(f, ",%.9g", swap[k]);
        fprintf(f, ",%s\n", infile);
        fclose(f);
    }
    if (swap[128] >= 2016.0f) {
        snprintf(path, sizeof path, "%s.lidar.csv", outname);
        f = fopen(path, "a");
        if (f) {
            fprintf(f, "%d,%.9g", calls, swap[1]);
            for (k = 2000; k < 2016; k++) fprintf(f, ",%.9g", swap[k]);
            fprintf(f, "\n");
            fclose(f);
        }
    }
    swap[41] = 0.11f; swap[42] = 0.12f; swap[43] = 0.13f;   /* records 42-44 */
    swap[44] = 0.2f;                                        /* record 45 */
    swap[46] = 1000.0f + (float)calls;                      /* record 47 */
    swap[34] = (swap[1] >= 0.25f && swap[1] < 0.3f) ? 0.0f : 1.0f;  /* record 35 */
    if (strstr(infile, "PROBE_STOP.IN") && swap[1] >= 0.5f) {
        *fail = -1;
        strcpy(msg, "probe: stop requested by its input file");
    }
    if (strstr(infile, "PROBE_EXIT.IN") && swap[1] >= 0.5f) {
        printf("probe: giving up at t = %.2f s\n", swap[1]);
        fflush(stdout);
        exit(3);
    }
    if (strstr(infile, "PROBE_CRASH.IN") && swap[1] >= 0.5f) {
        printf("probe: about to crash\n");
        fflush(stdout);
        *(volatile int *)0 = 1;
    }
    if (strstr(infile, "PROBE_HANG.IN") && swap[1] >= 0.5f) {
        for (;;) pause();
    }
    if (strstr(infile, "PROBE_SPIN.IN") && swap[1] >= 0.5f) {
        for (volatile unsigned long n = 0;; n++) { }
    }
}
