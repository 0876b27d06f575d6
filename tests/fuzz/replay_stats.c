/*
 * replay_stats.c - runs fuzz_core's input files through the target without
 * libFuzzer and prints how often each status and each controller step was
 * seen, so a corpus can be judged by what it reaches (docs/ROBUSTNESS.md);
 * built as replay_stats_fixed (FUZZ_CORE_FIXED=1), on the fixed-point core,
 * also how many frames the differential check compared.
 *
 * usage: replay_stats FILE_OR_DIR...
 */
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "spvs/spvs.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
extern unsigned long fuzz_core_status_seen[SPVS_STATUS_COUNT];
extern unsigned long fuzz_core_step_seen[8];
#if defined(FUZZ_CORE_FIXED) && FUZZ_CORE_FIXED
extern unsigned long fuzz_core_diff_compared;
extern unsigned long fuzz_core_diff_parted;
#endif

static unsigned long g_files;

static void run_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "replay_stats: cannot open %s\n", path);
        exit(2);
    }
    static uint8_t buf[1 << 20];
    size_t n = fread(buf, 1, sizeof(buf), f);
    fclose(f);
    LLVMFuzzerTestOneInput(buf, n);
    g_files++;
}

static void run_path(const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        fprintf(stderr, "replay_stats: no such file or folder: %s\n", path);
        exit(2);
    }
    if (!S_ISDIR(st.st_mode)) {
        run_file(path);
        return;
    }
    DIR *d = opendir(path);
    if (!d) {
        fprintf(stderr, "replay_stats: cannot read %s\n", path);
        exit(2);
    }
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.') {
            continue;
        }
        char full[4096];
        snprintf(full, sizeof(full), "%s/%s", path, e->d_name);
        run_file(full);
    }
    closedir(d);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: replay_stats FILE_OR_DIR...\n");
        return 2;
    }
    for (int i = 1; i < argc; i++) {
        run_path(argv[i]);
    }
    unsigned long calls = 0;
    for (int k = 0; k < SPVS_STATUS_COUNT; k++) {
        calls += fuzz_core_status_seen[k];
    }
    printf("replay_stats: %lu inputs, %lu core calls\n", g_files, calls);
    for (int k = 0; k < SPVS_STATUS_COUNT; k++) {
        printf("  status %-22s %lu\n", spvs_status_str(-k), fuzz_core_status_seen[k]);
    }
    for (int k = 1; k <= 5; k++) {
        printf("  step %d                   %lu\n", k, fuzz_core_step_seen[k]);
    }
#if defined(FUZZ_CORE_FIXED) && FUZZ_CORE_FIXED
    printf("  frames compared with the float core  %lu (inputs whose times parted: %lu)\n",
           fuzz_core_diff_compared, fuzz_core_diff_parted);
#endif
    return 0;
}
