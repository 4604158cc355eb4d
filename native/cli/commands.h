/*
 * commands.h - the skinpack subcommands. main.c dispatches on argv[1]; each command gets
 * argc/argv with argv[0] = the command name and returns the process exit status
 * (0 success, 1 bad input or failure, 2 usage error).
 */
#ifndef SKINPACK_CLI_COMMANDS_H
#define SKINPACK_CLI_COMMANDS_H

#ifdef __cplusplus
extern "C" {
#endif

int skinpack_cmd_info(int argc, char** argv);       /* cli_info.c */
int skinpack_cmd_compress(int argc, char** argv);   /* cli_compress.c */
int skinpack_cmd_decompress(int argc, char** argv); /* cli_decompress.c */
int skinpack_cmd_table2(int argc, char** argv);     /* cli_table2.c (the paper's Table 2) */
int skinpack_cmd_bench(int argc, char** argv);      /* cli_bench.c */

#ifdef __cplusplus
}
#endif

#endif /* SKINPACK_CLI_COMMANDS_H */
