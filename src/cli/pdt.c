/* pdt — command-line entry point: `pdt COMMAND [ARGS]`, dispatched through
 * the table below; each command lives in its own cmd_*.c. */
#include <stdio.h>
#include <string.h>

#include "cli.h"

static const pdt_cli_cmd commands[] = {
    { "triangulate", pdt_cmd_triangulate, "Delaunay triangulation T* of a point file" },
    { "hull", pdt_cmd_hull, "convex hull by Graham's scan (Version B)" },
    { "check", pdt_cmd_check, "verify that a triangle file is the Delaunay triangulation T*" },
    { "gen", pdt_cmd_gen, "generate a point set (uniform, grid, circle, ...)" },
    { "trace", pdt_cmd_trace, "look into a traced run folder: info, dump, check, export" },
};

static void usage(FILE *f)
{
    fprintf(f, "usage: pdt COMMAND [ARGS]   (pdt COMMAND --help for details)\n\n"
               "Exact Delaunay triangulation of points with 32-bit integer coordinates.\n\n"
               "commands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        fprintf(f, "  %-12s %s\n", commands[i].name, commands[i].summary);
    fprintf(f, "\noptions: --help, --version\n"
               "exit status: 0 success, 1 check failed, 2 usage or input error\n");
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return PDT_EXIT_USAGE;
    }
    const char *name = argv[1];
    if (strcmp(name, "--version") == 0 || strcmp(name, "version") == 0) {
        printf("pdt %s\n", PDT_VERSION);
        return PDT_EXIT_OK;
    }
    if (strcmp(name, "--help") == 0 || strcmp(name, "-h") == 0 || strcmp(name, "help") == 0) {
        usage(stdout);
        return PDT_EXIT_OK;
    }
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (strcmp(name, commands[i].name) == 0) return commands[i].fn(argc - 1, argv + 1);
    fprintf(stderr, "pdt: unknown command '%s'\n\n", name);
    usage(stderr);
    return PDT_EXIT_USAGE;
}
