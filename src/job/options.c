/* options.c - the words of a job's options (rt/job/options.h): the AOV
 * names, which name the --aov flag's list, the EXR layers, the side files
 * (NAME.albedo.pfm) and a part's layers, and the lookup from a name to its
 * AOV that the flags and `rt merge` share. */
#include "rt/job/options.h"

#include <string.h>

const char *const rt_aov_names[RT_AOV_COUNT] = {"albedo", "normal", "depth", "position", "variance", "spp"};

bool rt_aov_by_name(const char *name, size_t len, rt_aov_kind *out)
{
    for (int k = 0; k < RT_AOV_COUNT; k++)
        if (strlen(rt_aov_names[k]) == len && strncmp(name, rt_aov_names[k], len) == 0) {
            *out = (rt_aov_kind)k;
            return true;
        }
    return false;
}
