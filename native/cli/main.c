/* main.c - the skinpack command-line tool: dispatches to one command a source file. */
#include <stdio.h>
#include <string.h>

#include "commands.h"
#include "skinpack.h"

typedef struct command {
    const char* name;
    int (*run)(int argc, char** argv);
    const char* summary;
} command;

static const command commands[] = {
    {"info", skinpack_cmd_info, "IN [--json]                 skinning attributes of each skinned primitive"},
    {"compress", skinpack_cmd_compress, "IN -o OUT [options]     write SKINPACK_packed_skin (see 'compress --help')"},
    {"decompress", skinpack_cmd_decompress, "IN -o OUT             decode SKINPACK_packed_skin to JOINTS_0/WEIGHTS_0"},
#ifdef SKINPACK_CLI_HAVE_TABLE2
    {"table2", skinpack_cmd_table2, "[options]                 the paper's Table 2"},
#endif
#ifdef SKINPACK_CLI_HAVE_BENCH
    {"bench", skinpack_cmd_bench, "[options]                  codec benchmarks"},
#endif
};

static void usage(FILE* out) {
    fprintf(out, "skinpack %d.%d.%d - compression of skinning attributes (glTF SKINPACK_packed_skin)\n\n"
                 "usage:\n", SP_VERSION / 100, SP_VERSION / 10 % 10, SP_VERSION % 10);
    for (size_t i = 0; i < sizeof(commands) / sizeof(commands[0]); ++i)
        fprintf(out, "  skinpack %s %s\n", commands[i].name, commands[i].summary);
}

int main(int argc, char** argv) {
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "help") == 0) {
        usage(stdout);
        return 0;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("%d.%d.%d\n", SP_VERSION / 100, SP_VERSION / 10 % 10, SP_VERSION % 10);
        return 0;
    }
    for (size_t i = 0; i < sizeof(commands) / sizeof(commands[0]); ++i)
        if (strcmp(argv[1], commands[i].name) == 0) return commands[i].run(argc - 1, argv + 1);
    fprintf(stderr, "skinpack: unknown command '%s'\n\n", argv[1]);
    usage(stderr);
    return 2;
}
