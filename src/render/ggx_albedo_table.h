/* ggx_albedo_table.h - the GGX albedo tables that tools/ggx_albedo.c
 * generates (src/render/ggx_albedo_table.c, ggx_albedo_dielectric_table.c;
 * `make ggx-albedo-table`), for the lookups of ggx_albedo.c only: callers
 * use rt/render/ggx_albedo.h. Layout and sampling: that header. */
#ifndef RT_GGX_ALBEDO_TABLE_H
#define RT_GGX_ALBEDO_TABLE_H

#define RT_GGX_ALBEDO_N 32
#define RT_GGX_DIELECTRIC_NR 16

extern const float rt_ggx_albedo_table[RT_GGX_ALBEDO_N][RT_GGX_ALBEDO_N]; /* [alpha][mu] */
extern const float rt_ggx_albedo_avg_table[RT_GGX_ALBEDO_N];

extern const float rt_ggx_dielectric_table[2][RT_GGX_DIELECTRIC_NR][RT_GGX_ALBEDO_N][RT_GGX_ALBEDO_N];
extern const float rt_ggx_dielectric_avg_table[2][RT_GGX_DIELECTRIC_NR][RT_GGX_ALBEDO_N];
extern const float rt_ggx_dielectric_ms_table[RT_GGX_DIELECTRIC_NR][RT_GGX_ALBEDO_N];

#endif
