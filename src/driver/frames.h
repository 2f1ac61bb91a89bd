/* frames.h - `--frames A:B` (driver-private; docs/farm.md, "Frames"):
 * the output name of frame N from a printf-style pattern, and a frame's
 * time. Each frame is rendered as its own render (load, prepare, render,
 * write), so any launcher that splits parts can split frames alike.
 *
 *   char name[1024];
 *   if (!frames_name("out.%04d.png", 7, name, sizeof name)) ...   // "out.0007.png"
 *   frames_name("out.####.png", 7, name, sizeof name);               // the same
 *   double t = frames_time(7, 24.0);                             // 7 / 24 s: the --frame-time of frame 7
 */
#ifndef RT_DRIVER_FRAMES_H
#define RT_DRIVER_FRAMES_H

#include <stdbool.h>
#include <stddef.h>

#include "rt/base/error.h"
#include "rt/scene/scene.h"

/* True when pattern holds exactly one frame number conversion (%d or
 * %0Nd, N from 1 to 9) and no other '%' but "%%"; or, without any '%',
 * one run of 1 to 9 '#' ("f.####.png" is "f.%04d.png"). */
bool frames_pattern_ok(const char *pattern);
/* The pattern with the frame number in, into out; false when the pattern
 * is not ok or the name does not fit. */
bool frames_name(const char *pattern, int frame, char *out, size_t size);
/* The pattern of the frames when -o is not given, from the output name a
 * single render would take (name): NAME.EXT -> NAME.%04d.EXT; false when
 * it does not fit. */
bool frames_default_pattern(const char *name, char *out, size_t size);
/* A frame's time in seconds: frame / fps. */
double frames_time(int frame, double fps);

#endif
