/* pdt — command-line entry point (placeholder until the CLI lands). */
#include <stdio.h>
#include <string.h>

#include "pdt/common.h"

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "--version") == 0) {
        printf("pdt %s\n", PDT_VERSION);
        return 0;
    }
    fprintf(stderr, "pdt: no commands yet\n");
    return 2;
}
