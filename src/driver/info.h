/* info.h - `rt --info FILE [FILE...]` (driver-private): what each file
 * contains and how `rt FILE` would render it, one block of `key: value`
 * lines a file, a blank line between.
 *
 *   if (a.info_path)
 *       return info_print(&a);   // 0, or 2 when any file failed to load (the others are still printed)
 */
#ifndef RT_DRIVER_INFO_H
#define RT_DRIVER_INFO_H

#include "args.h"

int info_print(const args *a);

#endif
