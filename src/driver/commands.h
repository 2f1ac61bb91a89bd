/* commands.h - rt's subcommands besides rendering, each a whole program:
 * main() hands over argc and argv shifted so that argv[0] is the command's
 * name, and returns what the command returns as the exit status. Each lives
 * in src/driver/cmd_NAME.c, its library work in the stage it belongs to.
 *
 *   if (argc > 1 && strcmp(argv[1], "compare") == 0)
 *       return rt_cmd_compare(argc - 1, argv + 1);
 */
#ifndef RT_DRIVER_COMMANDS_H
#define RT_DRIVER_COMMANDS_H

#include <stdio.h>

/* rt compare CANDIDATE REFERENCE [--max-rmse X] [--max-flip X] ...
 * (docs/compare.md): prints the metrics as key: value lines on stdout.
 * Exit status 0 when every threshold given holds, 1 when one fails, 2 for
 * bad input (flags, unreadable images, different sizes). */
int rt_cmd_compare(int argc, char **argv);

/* The same, printing to `out` and `errs` instead of stdout and stderr (tests). */
int rt_cmd_compare_to(int argc, char **argv, FILE *out, FILE *errs);

/* rt convert IN OUT [--exposure EV] [--tonemap NAME] [--half]: an image from
 * one format to another (EXR, PFM, HDR in; PNG, PFM, HDR, EXR out). Exit
 * status 0 when written, 2 for bad input. */
int rt_cmd_convert(int argc, char **argv);
int rt_cmd_convert_to(int argc, char **argv, FILE *out, FILE *errs);

/* rt merge PART... -o OUT [--exposure EV] [--tonemap NAME] [--half]
 * (docs/farm.md): the parts of one render into its image. Exit status 0
 * when written, 2 when the parts do not make one image (nothing written). */
int rt_cmd_merge(int argc, char **argv);
int rt_cmd_merge_to(int argc, char **argv, FILE *out, FILE *errs);

#endif
