/* rt/scene.h - the scene as flat tables: everything a render reads.
 *
 * A scene is a set of arrays, each with its count, in the spirit of cgltf and
 * yocto-gl: no per-object allocations, no pointers between records (records
 * refer to each other by index). Loaders (scene_parse.c, gltf.c, mesh_obj.c,
 * mesh_ply.c, mesh_off.c) append to these tables; the kd-tree and the
 * renderer only read them.
 *
 *   Geometry    vertices (SoA-ish attribute arrays), triangles (index triplets,
 *               material, flags), spheres and quads (structure-of-arrays).
 *   Appearance  materials (one table for the text format and glTF alike),
 *               textures (image, wrap, filter), images (decoded pixels, once).
 *   Light       lights (point, directional, spot, area over a quad) and a
 *               constant or image environment.
 *   View        the camera. How to render the scene (resolution, samples,
 *               ...) is not the scene's but the render stage's.
 *
 * Primitive ids: one id space over all kinds, used by the kd-tree and hits.
 * Ids [0, T) are triangles, [T, T+S) spheres, [T+S, T+S+Q) quads, where
 * T, S, Q are the counts at kd-tree build time (see rt_prim_kind()).
 *
 * Instances (rt/scene/instance.h): an object is a run of triangles (and
 * their vertices) kept in its own space and flagged RT_TRI_OBJECT; only its
 * instances, each an affine transform, place it in the world. The kd-tree
 * gives each object its own tree and puts the instances in the top level;
 * a hit on an instance names the object's triangle (its id in [0, T)) and
 * the instance (rt_hit.inst). Everything that reads triangles as world
 * geometry skips the flagged ones (rt_scene_bounds does).
 *
 *   rt_scene s;
 *   rt_scene_init(&s);
 *   uint32_t m = rt_scene_add_material(&s, &mat);
 *   rt_scene_add_sphere(&s, rt_v3(0, 1, 0), 1.0f, m);
 *   ...
 *   rt_scene_free(&s);
 */
#ifndef RT_SCENE_H
#define RT_SCENE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rt/base/error.h"
#include "rt/base/vec.h"
#include "rt/scene/density_grid.h"

#define RT_NONE UINT32_MAX /* "no index": no texture, no hit, no material */

/* ---------------------------------------------------------------- view */

typedef struct rt_camera {
    rt_vec3 position, look_at, up;
    float vfov_deg;       /* vertical field of view, degrees */
    float aperture;       /* lens diameter; 0 = pinhole */
    float focus_distance; /* 0 = distance from position to look_at */
    float aspect_ratio;   /* width / height the camera was made for (glTF); 0 = none, follow the image */
    float shutter_open, shutter_close; /* seconds from the frame time; equal = no motion blur (the default 0 0) */
} rt_camera;

/* ---------------------------------------------------------- environment */

/* What rays that leave the scene see, and the whitted renderer's ambient
 * light: scene content, written by the scene format's `background`,
 * `environment` and `ambient_light` statements (the render stage's table
 * of statements stores them here). The image itself is
 * a texture of the scene (io's rt_environment_image_load loads the file). */
typedef struct rt_scene_environment {
    rt_vec3 background;   /* radiance of rays that leave the scene */
    uint32_t environment_texture; /* lat-long image, RT_NONE for constant background */
    char environment_file[4096];  /* the `environment` statement's file, "" = none; io loads it into environment_texture */
    float environment_strength;
    /* whitted: ambient radiance that materials' `ambient` coefficient
     * reflects. Unset (the default): the background's radiance, i.e. the
     * constant environment (background * environment_strength) or the mean
     * of the environment image (see docs/shading.md). */
    rt_vec3 ambient_light;
    bool ambient_light_set;
    /* `scene_medium NAME`: the participating medium (index into the scene's
     * media) the camera sits in and that fills everything no boundary
     * encloses; RT_NONE = vacuum */
    uint32_t medium;
} rt_scene_environment;

/* The defaults: black background, no image, strength 1, ambient unset, no medium. */
void rt_scene_environment_default(rt_scene_environment *e);

/* ------------------------------------------------------------ textures */

typedef enum rt_wrap { RT_WRAP_REPEAT = 0, RT_WRAP_CLAMP, RT_WRAP_MIRROR } rt_wrap;
typedef enum rt_filter { RT_FILTER_BILINEAR = 0, RT_FILTER_NEAREST } rt_filter;

/* Decoded pixels, loaded once per file (or per embedded buffer). Either
 * rgba8 (LDR, 4 bytes a texel, values as stored: sRGB decode happens on
 * lookup for colour slots) or rgbaf (HDR, linear float) is set. */
typedef struct rt_image {
    int width, height;
    uint8_t *rgba8;
    float *rgbaf;
    char name[256]; /* path or "file.glb#image3", for messages and caching */
    int *shares;    /* NULL: the pixels are this scene's; else how many scenes hold them (rt_scene_share_images) */
} rt_image;

/* A texture: which image, how it is sampled, or a procedural pattern. */
typedef enum rt_texture_kind { RT_TEX_IMAGE = 0, RT_TEX_CONSTANT, RT_TEX_CHECKER } rt_texture_kind;

typedef struct rt_texture {
    rt_texture_kind kind;
    uint32_t image;          /* RT_TEX_IMAGE: index into images */
    rt_wrap wrap_s, wrap_t;
    rt_filter filter;
    rt_vec4 color_a, color_b; /* constant colour; checker's two colours */
    float checker_scale;      /* checker squares per UV unit */
} rt_texture;

/* A material's use of a texture. */
typedef struct rt_texture_slot {
    uint32_t texture;    /* RT_NONE = no texture */
    uint8_t texcoord;    /* UV set 0 or 1 */
    /* UV transform (KHR_texture_transform): uv' = (m0*u + m1*v + m2, m3*u + m4*v + m5) */
    float uv_transform[6];
} rt_texture_slot;

/* ----------------------------------------------------------- materials */

typedef enum rt_alpha_mode { RT_ALPHA_OPAQUE = 0, RT_ALPHA_MASK, RT_ALPHA_BLEND } rt_alpha_mode;

/* The path tracer's scattering model (docs/path-tracer.md): the glTF
 * metallic-roughness BRDF (the default, zero), a pure Lambertian
 * albedo / pi with no specular lobe (`bsdf lambert`), a conductor with a
 * complex index of refraction eta + i k per channel (`bsdf conductor`), or
 * clear glass with an interior and exterior index, absorption inside and
 * radiance scaled by 1 / eta^2 across the interface (`bsdf dielectric`), or
 * a dielectric coat over a Lambertian base with the internal reflections
 * between them summed (`bsdf plastic`). */
typedef enum rt_bsdf_model {
    RT_BSDF_GLTF = 0, RT_BSDF_LAMBERT, RT_BSDF_CONDUCTOR, RT_BSDF_DIELECTRIC, RT_BSDF_PLASTIC,
    /* `bsdf null`: no surface at all, only the boundary of a participating
     * medium (interior_medium): light goes straight through unbent. The
     * parser makes it alpha-cut everywhere (alpha_mode mask, cutoff 2), so
     * integrators that do not trace media never see it. */
    RT_BSDF_NULL
} rt_bsdf_model;

/* Smith masking-shadowing term of the microfacet models. */
typedef enum rt_smith { RT_SMITH_CORRELATED = 0, RT_SMITH_SEPARABLE } rt_smith;

/* Texture slots of the glTF material extensions (rt_material.ext_tex),
 * with the channel each reads. */
typedef enum rt_ext_slot {
    RT_XTEX_CLEARCOAT = 0,          /* R: times clearcoat */
    RT_XTEX_CLEARCOAT_ROUGHNESS,    /* G: times clearcoat_roughness */
    RT_XTEX_CLEARCOAT_NORMAL,       /* tangent-space normal map of the coat */
    RT_XTEX_SPECULAR,               /* A: times specular_weight */
    RT_XTEX_SPECULAR_COLOR,         /* RGB (sRGB): times specular_color */
    RT_XTEX_SHEEN_COLOR,            /* RGB (sRGB): times sheen_color */
    RT_XTEX_SHEEN_ROUGHNESS,        /* A: times sheen_roughness */
    RT_XTEX_ANISOTROPY,             /* RG: direction in tangent space (2c - 1), B: times anisotropy */
    RT_XTEX_IRIDESCENCE,            /* R: times iridescence */
    RT_XTEX_IRIDESCENCE_THICKNESS,  /* G: mix of thickness min .. max */
    RT_XTEX_DIFFUSE_TRANSMISSION,   /* A: times diffuse_transmission */
    RT_XTEX_DIFFUSE_TRANSMISSION_COLOR, /* RGB (sRGB): times diffuse_transmission_color */
    RT_XTEX_COUNT
} rt_ext_slot;

/* One material table for every source. The Phong fields drive the whitted
 * renderer; the PBR fields drive the path tracer; colour, textures,
 * reflection and transmission are read by both. rt_material_default() gives
 * the documented defaults (the old renderer's constants: ambient 0.4,
 * diffuse 0.8, specular 0.05). */
typedef struct rt_material {
    char name[64];
    rt_vec3 color;          /* diffuse / base colour, linear RGB */
    float alpha;            /* base colour alpha */
    /* Phong */
    float ambient, diffuse, specular, shininess;
    float reflectivity;     /* mirror reflection weight, 0..1 */
    float transmission;     /* refraction weight, 0..1 */
    rt_vec3 transmission_color; /* filter colour for light passing through */
    float ior;              /* index of refraction of the inside */
    /* PBR (glTF metallic-roughness and extensions) */
    float metallic, roughness;
    rt_vec3 emission;       /* emitted radiance = emission * emission_strength */
    float emission_strength;
    float normal_scale;
    float occlusion_strength;
    rt_alpha_mode alpha_mode;
    float alpha_cutoff;
    bool double_sided;
    bool unlit;
    rt_bsdf_model bsdf;     /* path tracer: glTF metallic-roughness (default) or pure Lambert */
    /* conductor (bsdf conductor): complex IOR relative to the outside, GGX
     * alphas along the tangent and bitangent (negative: roughness^2) */
    rt_vec3 eta, k;
    float alpha_u, alpha_v;
    rt_smith smith;
    /* dielectric and plastic: ior is the inside's (the coat's) index */
    float exterior_ior;     /* index outside (default 1) */
    int priority;           /* dielectric: nested-media priority, higher wins (rt/render/medium.h) */
    /* participating media on either side (indices into the scene's media,
     * RT_NONE = none): inside a closed dielectric or null boundary, and
     * outside it where that is not the scene's medium */
    uint32_t interior_medium, exterior_medium;
    rt_vec3 absorption;     /* absorption coefficient inside, per scene unit (adds to attenuation_*) */
    float thickness;        /* KHR_materials_volume */
    bool thin_walled;       /* glTF: no volume (thickness 0), transmission goes straight through; scene text: false */
    rt_vec3 attenuation_color;
    float attenuation_distance; /* INFINITY = no absorption */
    /* random-walk subsurface scattering (rt/scene/subsurface.h): a
     * homogeneous medium inside the boundary, made from these by
     * rt_subsurface_attach when `subsurface` is set */
    bool subsurface;
    rt_vec3 subsurface_albedo;  /* multiple-scattering albedo, each in [0, 1] */
    rt_vec3 subsurface_radius;  /* mean free path per channel, scene units; 0: from attenuation_* (glTF) */
    float subsurface_g;         /* Henyey-Greenstein anisotropy */
    /* textures */
    rt_texture_slot base_color_tex; /* sRGB colour */
    rt_texture_slot metal_rough_tex; /* B = metal, G = roughness */
    rt_texture_slot normal_tex;      /* tangent-space normal map */
    rt_texture_slot occlusion_tex;   /* R */
    rt_texture_slot emissive_tex;    /* sRGB colour */
    rt_texture_slot transmission_tex; /* R */
    /* glTF PBR-next extensions (docs/gltf.md, docs/shading.md); the
     * defaults leave the core glTF BRDF exactly as without them */
    float clearcoat;              /* KHR_materials_clearcoat: coat weight (0) */
    float clearcoat_roughness;    /* coat roughness (0: a mirror coat) */
    float clearcoat_normal_scale; /* scale of the coat's normal map (1) */
    float specular_weight;        /* KHR_materials_specular: specularFactor (1) */
    rt_vec3 specular_color;       /* specularColorFactor (1, 1, 1): scales the dielectric F0 */
    rt_vec3 sheen_color;          /* KHR_materials_sheen: sheenColorFactor (0: no sheen) */
    float sheen_roughness;        /* sheenRoughnessFactor (0) */
    float anisotropy;             /* KHR_materials_anisotropy: anisotropyStrength (0) */
    float anisotropy_rotation;    /* anisotropyRotation, radians from the tangent (0) */
    float iridescence;            /* KHR_materials_iridescence: iridescenceFactor (0) */
    float iridescence_ior;        /* film index (1.3) */
    float iridescence_thickness_min, iridescence_thickness_max; /* film thickness, nm (100, 400) */
    float dispersion;             /* KHR_materials_dispersion: 20 / Abbe number (0: none) */
    float diffuse_transmission;   /* KHR_materials_diffuse_transmission factor (0) */
    rt_vec3 diffuse_transmission_color; /* (1, 1, 1) */
    rt_texture_slot ext_tex[RT_XTEX_COUNT]; /* the extensions' textures, by rt_ext_slot */
    bool extended;                /* rt_material_extended(), set once by the loader: the BSDF reads the fields above */
} rt_material;

void rt_material_default(rt_material *m, const char *name);
/* True when some extension field or texture above differs from its default
 * (loaders store it in `extended`, so a hit need not check each field). */
bool rt_material_extended(const rt_material *m);

/* Named metals for `bsdf conductor` (`metal NAME`): complex IOR eta + i k at
 * the red, green and blue wavelengths 650, 550 and 450 nm, from
 * RefractiveIndex.INFO's "3D" data set (M. N. Polyanskiy, refractiveindex.info
 * database, Sci. Data 11, 94 (2024)), as tabulated by C. Hindefjord, "RGB IOR
 * values for common metals"; Cr, Ni and W from E. D. Palik (ed.), "Handbook
 * of Optical Constants of Solids" (1985), as tabulated in Mitsuba 0.6's
 * spectral data, interpolated linearly at the same three wavelengths. The
 * default conductor is Cu (as pbrt-v4's). */
typedef struct rt_metal {
    const char *name;
    rt_vec3 eta, k;
} rt_metal;
extern const rt_metal rt_metals[];
extern const size_t rt_metal_count;
void rt_texture_slot_none(rt_texture_slot *slot);

/* -------------------------------------------------------------- lights */

typedef enum rt_light_kind {
    RT_LIGHT_POINT = 0,
    RT_LIGHT_DIRECTIONAL,
    RT_LIGHT_SPOT,
    RT_LIGHT_AREA, /* one-sided emitter over a parallelogram: corner + edge_u + edge_v */
} rt_light_kind;

typedef struct rt_light {
    rt_light_kind kind;
    rt_vec3 color;       /* linear RGB, multiplied by intensity */
    float intensity;     /* point/spot: W/sr-like intensity; directional: irradiance; area: radiance */
    rt_vec3 position;    /* point, spot; area: corner */
    rt_vec3 direction;   /* directional, spot: the direction light travels */
    rt_vec3 edge_u, edge_v; /* area: the quad's two edges; emits towards cross(edge_u, edge_v) */
    float inner_cone, outer_cone; /* spot, radians */
    float range;         /* 0 = infinite */
    uint32_t quad;       /* area: the visible quad primitive (index into quads), RT_NONE if none */
} rt_light;

/* --------------------------------------------------------------- media */

/* A participating medium (docs/media.md): absorption and scattering
 * coefficients per RGB channel and per world unit (the scene format's
 * `scale` already applied) at density 1, a Henyey-Greenstein anisotropy,
 * and a density that is 1 everywhere (homogeneous) or a voxel grid placed
 * in the world by index_to_world (the file's own map composed with the
 * medium line's transform). The render stage samples it as an rt_volume
 * (rt/render/volume.h). */
#define RT_MEDIUM_G_MAX 0.999f /* |g| at most (rt/render/phase.h's RT_HG_G_MAX) */

typedef enum rt_medium_kind { RT_MEDIUM_HOMOGENEOUS = 0, RT_MEDIUM_GRID } rt_medium_kind;

typedef struct rt_medium_def {
    char name[64];
    rt_medium_kind kind;
    rt_vec3 sigma_a, sigma_s;  /* per world unit, >= 0 */
    float g;                   /* in (-1, 1) */
    rt_density_grid grid;      /* RT_MEDIUM_GRID: owned by the scene */
    rt_mat4 index_to_world;    /* RT_MEDIUM_GRID: the grid's index space to the world */
    rt_mat4 world_to_index;    /* RT_MEDIUM_GRID: its inverse (the loader sets both) */
} rt_medium_def;

/* ------------------------------------------------------------ geometry */

/* Per-vertex attributes. position, normal and uv0 always exist for every
 * vertex; uv1, tangent and color are NULL until some loader enables them
 * (rt_scene_enable_attr), after which every vertex has one (defaults:
 * uv (0,0), tangent (0,0,0,0) = none, colour (1,1,1,1)). */
typedef struct rt_vertices {
    size_t count, cap;
    rt_vec3 *position;
    rt_vec3 *normal;
    rt_vec2 *uv0;
    rt_vec2 *uv1;
    rt_vec4 *tangent; /* xyz tangent, w = bitangent sign (glTF convention) */
    rt_vec4 *color;
} rt_vertices;

enum rt_vertex_attr { RT_ATTR_UV1 = 1, RT_ATTR_TANGENT = 2, RT_ATTR_COLOR = 4 };

/* Per-triangle flags: which vertex attributes are meaningful for it. */
enum rt_triangle_flags {
    RT_TRI_SMOOTH = 1,  /* interpolate vertex normals (else flat geometric normal) */
    RT_TRI_TANGENT = 2, /* vertex tangents are valid */
    RT_TRI_COLOR = 4,   /* vertex colours are valid */
    RT_TRI_UV = 8,      /* vertex UVs are meaningful (else generated) */
    RT_TRI_OBJECT = 16, /* in an object's own space: placed only by instances (rt/scene/instance.h) */
};

typedef struct rt_triangles {
    size_t count, cap;
    uint32_t *index;    /* 3 vertex indices per triangle */
    uint32_t *material;
    uint8_t *flags;
} rt_triangles;

typedef struct rt_spheres {
    size_t count, cap;
    float *cx, *cy, *cz, *radius;
    uint32_t *material;
} rt_spheres;

/* A parallelogram: corner p, edges u and v; points p + s*u + t*v, s,t in
 * [0,1]; UV = (s, t); normal = normalize(cross(u, v)). */
typedef struct rt_quads {
    size_t count, cap;
    float *px, *py, *pz;
    float *ux, *uy, *uz;
    float *vx, *vy, *vz;
    uint32_t *material;
} rt_quads;

/* -------------------------------------------------------------- scene */

typedef struct rt_scene {
    rt_camera camera;
    bool camera_set;   /* false: frame the scene bounds automatically */
    rt_scene_environment environment;

    rt_material *materials; size_t material_count, material_cap;
    rt_texture *textures;   size_t texture_count, texture_cap;
    rt_image *images;       size_t image_count, image_cap;
    rt_light *lights;       size_t light_count, light_cap;
    rt_camera *cameras;     size_t camera_count, camera_cap; /* from models (glTF cameras) */
    rt_medium_def *media;   size_t medium_count, medium_cap; /* participating media (grids owned) */

    rt_vertices vertices;
    rt_triangles triangles;
    rt_spheres spheres;
    rt_quads quads;

    /* instancing (rt/scene/instance.h): objects in their own space, and
     * their placements */
    struct rt_object *objects;     size_t object_count, object_cap;
    struct rt_instance *instances; size_t instance_count, instance_cap;
} rt_scene;

void rt_scene_init(rt_scene *s);
void rt_scene_free(rt_scene *s);

/* Table appends. Each returns the new record's index, or RT_NONE when out of
 * memory. */
uint32_t rt_scene_add_material(rt_scene *s, const rt_material *m);
uint32_t rt_scene_find_material(const rt_scene *s, const char *name); /* RT_NONE if absent */
uint32_t rt_scene_add_texture(rt_scene *s, const rt_texture *t);
uint32_t rt_scene_add_image(rt_scene *s, const rt_image *img); /* takes ownership of the pixels */
uint32_t rt_scene_add_light(rt_scene *s, const rt_light *l);
/* Takes ownership of the medium's grid (freed with the scene), also on failure. */
uint32_t rt_scene_add_medium(rt_scene *s, rt_medium_def *m);
uint32_t rt_scene_find_medium(const rt_scene *s, const char *name); /* RT_NONE if absent */
/* Whether a path must trace participating media: some medium is used by
 * the scene or a material, or some material is a null boundary. */
bool rt_scene_has_media(const rt_scene *s);
/* Appends every image of `from` to s, sharing the decoded pixels (counted:
 * the last scene freed frees them), so loading the same files into s finds
 * them decoded (motion-blur slices, rt/job/motion.h). false when out of
 * memory: s keeps the images shared so far, freed with it. */
bool rt_scene_share_images(rt_scene *s, rt_scene *from);
uint32_t rt_scene_add_camera(rt_scene *s, const rt_camera *c);
uint32_t rt_scene_add_sphere(rt_scene *s, rt_vec3 center, float radius, uint32_t material);
uint32_t rt_scene_add_quad(rt_scene *s, rt_vec3 corner, rt_vec3 edge_u, rt_vec3 edge_v, uint32_t material);

/* Appends n vertices with default attributes (normal 0, uv 0, colour 1) and
 * returns the index of the first, or RT_NONE. */
uint32_t rt_scene_add_vertices(rt_scene *s, size_t n);
/* Makes the optional attribute arrays exist (RT_ATTR_* bits). false = out of memory. */
bool rt_scene_enable_attr(rt_scene *s, unsigned attrs);
/* Appends a triangle over existing vertices; RT_NONE when out of memory. */
uint32_t rt_scene_add_triangle(rt_scene *s, uint32_t a, uint32_t b, uint32_t c, uint32_t material, uint8_t flags);
/* Reserves room for n more triangles (avoids repeated growth). */
bool rt_scene_reserve_triangles(rt_scene *s, size_t n);

/* Undoing a load that failed half way: every loader marks the scene before
 * it appends anything and rolls back to the mark on any error, so that a
 * failed load leaves the scene exactly as it was.
 *
 *   rt_scene_mark mark = rt_scene_mark_of(s);
 *   if ((r = append_things(s, ...)) != RT_OK)
 *       rt_scene_rollback(s, &mark);
 *
 * The mark holds every table's count, which optional vertex attribute
 * arrays existed, and the camera and environment (which the scene format sets).
 * Rolling back truncates every table to its count (images beyond it free
 * their pixels), frees the attribute arrays enabled since, and restores the
 * camera and environment. Marks nest: a loader inside another rolls back its
 * own part. */
typedef struct rt_scene_mark {
    size_t materials, textures, images, lights, cameras, media;
    size_t vertices, triangles, spheres, quads;
    size_t objects, instances;
    unsigned vertex_attrs; /* RT_ATTR_* arrays that existed */
    bool camera_set;
    rt_camera camera;
    rt_scene_environment environment;
} rt_scene_mark;

rt_scene_mark rt_scene_mark_of(const rt_scene *s);
void rt_scene_rollback(rt_scene *s, const rt_scene_mark *mark);

/* Primitive id space (see the top of this file). */
typedef enum rt_prim_kind { RT_PRIM_TRIANGLE = 0, RT_PRIM_SPHERE, RT_PRIM_QUAD } rt_prim_kind;
static inline size_t rt_scene_prim_count(const rt_scene *s)
{
    return s->triangles.count + s->spheres.count + s->quads.count;
}
static inline rt_prim_kind rt_prim_kind_of(const rt_scene *s, uint32_t prim, uint32_t *local)
{
    size_t t = s->triangles.count, sp = s->spheres.count;
    if (prim < t) { *local = prim; return RT_PRIM_TRIANGLE; }
    if (prim < t + sp) { *local = (uint32_t)(prim - t); return RT_PRIM_SPHERE; }
    *local = (uint32_t)(prim - t - sp);
    return RT_PRIM_QUAD;
}
static inline rt_vec3 rt_tri_vertex(const rt_scene *s, size_t tri, int corner)
{
    return s->vertices.position[s->triangles.index[3 * tri + (size_t)corner]];
}
/* Bounds of one primitive (an object's triangle: in its object's space),
 * and the world bounds of the whole scene (primitives and instances; not
 * the objects' own triangles). */
rt_box rt_scene_prim_bounds(const rt_scene *s, uint32_t prim);
rt_box rt_scene_bounds(const rt_scene *s);

/* Points the camera at the scene's bounds from the front (+z side), for
 * models without a camera, framed for an image of this aspect ratio
 * (width / height). */
void rt_scene_frame_camera(rt_scene *s, float aspect);

/* What that camera must see of a scene over several poses (the frames of
 * an animation), so that one camera frames them all: the union of their
 * bounds (the camera looks at its centre) and, for each of the four sides
 * of the view, the farthest any point reaches (the camera backs off until
 * every point of every pose is in view). Gathered pose by pose, the poses
 * need not be loaded together:
 *
 *   rt_frame_extent e;
 *   rt_frame_extent_init(&e, 4.0f / 3.0f);
 *   for each pose: rt_frame_extent_add(&e, &posed_scene);
 *   rt_scene_frame_camera_extent(&scene, &e);   // the same camera for every pose
 */
typedef struct rt_frame_extent {
    float aspect;   /* the image's width / height */
    rt_box bounds;  /* the union of the poses' bounds */
    float reach[4]; /* the largest dot(p, dir) + dot(p, right) / tan_h, - ..., + dot(p, up) / tan_v, - ... */
} rt_frame_extent;
void rt_frame_extent_init(rt_frame_extent *e, float aspect);
void rt_frame_extent_add(rt_frame_extent *e, const rt_scene *s);
/* The camera of rt_scene_frame_camera for every pose gathered in e. */
void rt_scene_frame_camera_extent(rt_scene *s, const rt_frame_extent *e);

#endif
