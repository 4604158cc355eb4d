/*
 * skinpack table2 [--json]: the paper's Table 2 (bits needed per sample spacing) and the Delta
 * values of its Table 3 (22- and 38-bit weights), computed by the library next to the
 * paper's printed numbers. docs/table2.md explains every difference.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "commands.h"
#include "skinpack.h"

#define COLUMNS 4
#define TABLE3_BUDGETS 2

static const char* const column_names[COLUMNS] = {"4x32-bit float", "4x16-bit fixed", "4x16-bit float",
                                                  "4x8-bit fixed"};
static const double column_inverse_delta[COLUMNS] = {16777216.0, 65535.0, 2048.0, 255.0};
static const sp_method table_methods[SP_METHOD_COUNT] = {SP_METHOD_FIXED, SP_METHOD_CUBE, SP_METHOD_POT,
                                                         SP_METHOD_ANY, SP_METHOD_OSS};
/* As printed in Kuth & Meyer, Table 2 and Table 3 (four weights). */
static const double paper_table2[SP_METHOD_COUNT][COLUMNS] = {
    {96, 64, 44, 32}, {72, 48, 33, 24}, {68, 44, 29, 20}, {67.4, 43.4, 28.4, 19.4}, {64.4, 40.8, 25.8, 16.8}};
static const uint32_t table3_bits[TABLE3_BUDGETS] = {22, 38};
static const double paper_table3[SP_METHOD_COUNT][TABLE3_BUDGETS] = {
    {0, 0}, {7.9e-3, 2.4e-4}, {2.6e-3, 6.1e-5}, {2.2e-3, 5.3e-5}, {1.2e-3, 2.9e-5}};

/* The paper counts 1/Delta samples per unit length (a float with a 24-bit significand is
 * matched by a 24-bit fixed-point number, 2^24 - 1 intervals), so a column is reached at a
 * spacing of 1 / (1/Delta - 1). */
static double paper_spacing(double inverse_delta)
{
    return 1.0 / (inverse_delta - 1.0);
}

int skinpack_cmd_table2(int argc, char** argv)
{
    int json = argc > 1 && strcmp(argv[1], "--json") == 0;
    if (argc > 2 || (argc == 2 && !json)) {
        fprintf(stderr, "usage: skinpack table2 [--json]\n");
        return 2;
    }
    double code_bits[SP_METHOD_COUNT][COLUMNS];
    double spacing[SP_METHOD_COUNT][TABLE3_BUDGETS];
    for (int m = 0; m < SP_METHOD_COUNT; ++m) {
        for (int c = 0; c < COLUMNS; ++c) {
            uint32_t bits;
            if (sp_required_bits(table_methods[m], 4, paper_spacing(column_inverse_delta[c]), &bits,
                                 &code_bits[m][c]) != SP_OK)
                return 1;
        }
        for (int b = 0; b < TABLE3_BUDGETS; ++b) {
            sp_codec codec;
            if (sp_codec_from_bits(table_methods[m], 4, table3_bits[b], &codec) != SP_OK) return 1;
            spacing[m][b] = codec.max_spacing;
        }
    }
    if (json) {
        printf("{\"table2\": {\"columns\": [");
        for (int c = 0; c < COLUMNS; ++c) printf("%s{\"name\": \"%s\", \"delta\": %.10g}", c ? ", " : "", column_names[c], 1.0 / column_inverse_delta[c]);
        printf("], \"rows\": [");
        for (int m = 0; m < SP_METHOD_COUNT; ++m) {
            printf("%s{\"method\": \"%s\", \"bits\": [", m ? ", " : "", sp_method_name(table_methods[m]));
            for (int c = 0; c < COLUMNS; ++c) printf("%s%.4f", c ? ", " : "", code_bits[m][c]);
            printf("], \"paper\": [");
            for (int c = 0; c < COLUMNS; ++c) printf("%s%g", c ? ", " : "", paper_table2[m][c]);
            printf("]}");
        }
        printf("]}, \"table3\": {\"weight_bits\": [22, 38], \"rows\": [");
        for (int m = 1; m < SP_METHOD_COUNT; ++m) {
            printf("%s{\"method\": \"%s\", \"delta\": [%.6g, %.6g], \"paper\": [%g, %g]}", m > 1 ? ", " : "",
                   sp_method_name(table_methods[m]), spacing[m][0], spacing[m][1], paper_table3[m][0],
                   paper_table3[m][1]);
        }
        printf("]}}\n");
        return 0;
    }
    printf("Table 2: bits for four weights at the precision of each format (ours / paper)\n");
    printf("%-6s", "");
    for (int c = 0; c < COLUMNS; ++c) printf(" | %-16s", column_names[c]);
    printf("\n");
    for (int m = 0; m < SP_METHOD_COUNT; ++m) {
        printf("%-6s", sp_method_name(table_methods[m]));
        for (int c = 0; c < COLUMNS; ++c) printf(" | %6.1f / %-7g", code_bits[m][c], paper_table2[m][c]);
        printf("\n");
    }
    printf("\nTable 3: sample spacing Delta of four weights in 22 and 38 bits (ours / paper)\n");
    for (int m = 1; m < SP_METHOD_COUNT; ++m)
        printf("%-6s | 22 bits: %.1e / %.1e | 38 bits: %.1e / %.1e\n", sp_method_name(table_methods[m]),
               spacing[m][0], paper_table3[m][0], spacing[m][1], paper_table3[m][1]);
    printf("\nOSS, 4 weights, 22 bits: N = 421, T(N) = %llu codes, spacing 0.5/(N-1) = %.3g\n",
           (unsigned long long)sp_oss_tetrahedron_count(421), 0.5 / 420);
    printf("Differences from the paper are explained in docs/table2.md.\n");
    return 0;
}
