/*
 * voxelkit.h: the C interface of voxelkit, voxelization with guaranteed topology.
 *
 * Install with `scripts/install.sh PREFIX`, then link with
 * `pkg-config --cflags --libs voxelkit` (shared library) or
 * `pkg-config --cflags --libs voxelkit-static` (static library), or from CMake:
 *
 *     find_package(voxelkit REQUIRED)
 *     target_link_libraries(app PRIVATE voxelkit::voxelkit)        # or voxelkit::voxelkit_static
 *
 * Conventions
 * - Every function that can fail returns a vk_status; VK_OK is 0. On failure,
 *   vk_last_error() returns a message naming what went wrong (the file and line of a bad
 *   OBJ, the face of a bad mesh, ...). The message belongs to the calling thread and stays
 *   valid until its next voxelkit call.
 * - Objects are opaque handles: vk_mesh, vk_grid, vk_options. Each is created by one
 *   function and released by its vk_*_free. Handles are checked on every call: NULL, a
 *   released handle, or a handle of the wrong kind gives VK_ERROR_INVALID_HANDLE instead of
 *   a crash, and releasing a handle twice is reported, not undefined. vk_*_free(NULL) is a
 *   no-op that returns VK_OK.
 * - Outputs are written only on success. Output pointers must not be NULL.
 * - No C++ exception and no Rust panic crosses this interface: an internal error comes back
 *   as VK_ERROR_INTERNAL with its message.
 * - Index space: voxel (i, j, k) is the unit cube centred on the integer point (i, j, k);
 *   world = origin + voxel_size * index. Leaves are 8x8x8 blocks laid out like OpenVDB's
 *   LeafNode: origin a multiple of 8, voxel n = x*64 + y*8 + z, mask word x, bit y*8 + z.
 * - Functions may be called from several threads at once on different handles. A handle may
 *   be read from several threads at once; it must not be freed while in use.
 */
#ifndef VOXELKIT_H
#define VOXELKIT_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum vk_status {
    VK_OK = 0,
    /* An argument is out of range, or a size does not match (the message says which). */
    VK_ERROR_INVALID_ARGUMENT = 1,
    /* NULL, released, or of the wrong kind. */
    VK_ERROR_INVALID_HANDLE = 2,
    /* A file could not be read or written. */
    VK_ERROR_IO = 3,
    /* A malformed input file or formula (file, line or column in the message). */
    VK_ERROR_PARSE = 4,
    /* A mesh the operation cannot use: empty, degenerate, open, non-manifold. */
    VK_ERROR_BAD_MESH = 5,
    /* The estimated memory exceeds what is available. */
    VK_ERROR_TOO_LARGE = 6,
    /* OpenVDB refused to read or write a .vdb file. */
    VK_ERROR_VDB = 7,
    /* The cancel flag was set, or the progress callback asked to stop. */
    VK_ERROR_CANCELLED = 8,
    /* A caller buffer is too small; the count needed is returned. */
    VK_ERROR_BUFFER_TOO_SMALL = 9,
    /* A bug in voxelkit (a caught panic); the message says where. */
    VK_ERROR_INTERNAL = 10
} vk_status;

typedef struct vk_mesh vk_mesh;
typedef struct vk_grid vk_grid;
typedef struct vk_options vk_options;

/* How vk_voxelize_mesh makes a surface. */
typedef enum vk_surface_method {
    /* Huang et al.'s 6- or 26-separating surface (see vk_options_set_separability). */
    VK_SURFACE_SEPARATING = 0,
    /* Jegathese et al.'s projective scan-lines: fast, colours, no separability guarantee. */
    VK_SURFACE_PROJECTIVE = 1
} vk_surface_method;

/* How vk_fill_mesh finds a solid. */
typedef enum vk_fill_method {
    /* The 26-separating surface plus everything the exterior flood cannot reach. */
    VK_FILL_FLOOD = 0,
    /* Depth layers with a stencil count: exact at voxel centres (inside voxels only). */
    VK_FILL_DEPTH_LAYERS = 1,
    /* The projective surface plus the beams between front and back faces along z. */
    VK_FILL_BEAM = 2
} vk_fill_method;

typedef enum vk_criterion {
    VK_CRITERION_HUANG = 0,  /* the paper's full vertex spheres and edge cylinders */
    VK_CRITERION_CLIPPED = 1 /* the same clipped to the face slabs: near-minimal */
} vk_criterion;

typedef enum vk_coordinates {
    VK_CARTESIAN = 0,   /* x y z */
    VK_SPHERICAL = 1,   /* r theta phi */
    VK_CYLINDRICAL = 2  /* r theta y */
} vk_coordinates;

/* How vk_grid_write_vdb_with compresses a .vdb. */
typedef enum vk_compression {
    VK_COMPRESSION_BLOSC = 0, /* OpenVDB's default */
    VK_COMPRESSION_ZIP = 1,
    VK_COMPRESSION_NONE = 2
} vk_compression;

typedef enum vk_boolean {
    VK_UNION = 0,
    VK_INTERSECTION = 1,
    VK_DIFFERENCE = 2
} vk_boolean;

/*
 * Progress of a long call: `done` of `total` work items (some methods estimate `total`; a
 * call that succeeds reports done == total last). Called from worker threads, never two at a time;
 * it must not throw or longjmp. Return 0 to go on, anything else to cancel (the call then
 * returns VK_ERROR_CANCELLED).
 */
typedef int (*vk_progress_fn)(uint64_t done, uint64_t total, void *user_data);

/* What a solid measures. Volumes in world units cubed. */
typedef struct vk_measures {
    uint64_t inside_voxels;
    uint64_t surface_voxels;
    double volume_inside;       /* the inside voxels only: a lower bound */
    double volume_with_surface; /* inside plus surface voxels: an upper bound */
} vk_measures;

/* The library version, e.g. "0.1.0" (static storage). */
const char *vk_version(void);

/* The message of the calling thread's last failure ("" after a success). */
const char *vk_last_error(void);

/* ---- meshes ---------------------------------------------------------------------------- */

/* Loads a mesh file by its extension: .obj (polygons, `l` polylines, `v x y z r g b`
 * colours), .stl (binary or ASCII), .ply, .off, .gltf or .glb (its buffers read only from
 * its own folder). */
vk_status vk_mesh_load(const char *path, vk_mesh **out);

/*
 * A triangle mesh from arrays: `positions` holds 3 * vertex_count doubles (x, y, z),
 * `triangles` 3 * triangle_count zero-based vertex indices. The arrays are copied.
 */
vk_status vk_mesh_from_triangles(const double *positions, size_t vertex_count,
                                 const uint32_t *triangles, size_t triangle_count,
                                 vk_mesh **out);

/* Vertex and face counts. */
vk_status vk_mesh_counts(const vk_mesh *mesh, size_t *vertices, size_t *faces);

/*
 * Copies a triangle mesh out: 3 * vertices doubles (x, y, z) into `positions` and
 * 3 * faces zero-based vertex indices into `triangles` (the counts of vk_mesh_counts).
 * VK_ERROR_INVALID_ARGUMENT when a face is not a triangle.
 */
vk_status vk_mesh_copy_triangles(const vk_mesh *mesh, double *positions, uint32_t *triangles);

vk_status vk_mesh_free(vk_mesh *mesh);

/* ---- options ---------------------------------------------------------------------------- */

/* Options with the defaults of voxelkit.OPTIONS (resolution 256, 26-separating, Huang's
 * criterion, no normals, separating surface, the block flood, 16 directions of double depth
 * layers, pre-split 8, blosc), all cores, no progress callback, no cancel flag. */
vk_status vk_options_new(vk_options **out);
vk_status vk_options_free(vk_options *options);

/* Voxels along the longest bounding-box axis (1 ..= 65536). Clears a voxel size. */
vk_status vk_options_set_resolution(vk_options *options, uint32_t resolution);
/* Voxel edge length in world units (> 0); replaces the resolution. */
vk_status vk_options_set_voxel_size(vk_options *options, double voxel_size);
/* 6 or 26. */
vk_status vk_options_set_separability(vk_options *options, int separability);
vk_status vk_options_set_criterion(vk_options *options, vk_criterion criterion);
/* Non-zero: separating surfaces carry the nearest primitive's normal per voxel (the projective
 * method refuses it with VK_ERROR_INVALID_ARGUMENT). */
vk_status vk_options_set_normals(vk_options *options, int normals);
vk_status vk_options_set_surface_method(vk_options *options, vk_surface_method method);
vk_status vk_options_set_fill_method(vk_options *options, vk_fill_method method);
/* The exterior flood of VK_FILL_FLOOD: non-zero `flooding_xyz` for Lai & Cheng's
 * FloodingXYZ with a GRAYSTACK of `graystack` entries (sweeps resume it when full), zero for
 * the block flood (the default). */
vk_status vk_options_set_flood(vk_options *options, int flooding_xyz, size_t graystack);
/* VK_FILL_DEPTH_LAYERS: 3 (the axes) to 16 directions (default 16), double layers with a
 * stencil count (non-zero, the default) or Karabassi's single layers (zero). */
vk_status vk_options_set_depth_layers(vk_options *options, uint32_t directions, int double_layers);
/* vk_voxelize_subdivision: each patch pre-split presplit x presplit (>= 1, default 8);
 * non-zero `enclose` refines until every voxel the surface touches is output. */
vk_status vk_options_set_subdivision(vk_options *options, uint32_t presplit, int enclose);
/* Worker threads for calls with these options (0: all cores, the default; at most 256). */
vk_status vk_options_set_threads(vk_options *options, uint32_t threads);
/* Refuse work whose estimated memory exceeds `mib` MiB (0: the memory available, the
 * default) with VK_ERROR_TOO_LARGE before anything large is allocated. */
vk_status vk_options_set_max_memory(vk_options *options, uint64_t mib);
/* Progress callback (NULL to remove) and the pointer it receives. */
vk_status vk_options_set_progress(vk_options *options, vk_progress_fn callback, void *user_data);
/*
 * A flag another thread sets to non-zero (with an atomic store) to cancel a long call;
 * NULL to remove. It must stay valid while calls with these options run.
 */
vk_status vk_options_set_cancel_flag(vk_options *options, const int32_t *flag);
/*
 * Distances instead of voxel sets: with a positive `band` (half width in voxels),
 * vk_voxelize_mesh and vk_fill_mesh make a level set, exact signed distances in world units
 * (negative inside, by the solid request's `inside` rule) on every voxel within `band`
 * voxels of the surface; vk_options_set_udf makes vk_voxelize_mesh give unsigned distances
 * (open meshes too). 0 turns them off; each turns the other off. Read the values with
 * vk_grid_copy_values; vk_grid_write_vdb writes the level set as the CLI's --sdf does.
 */
vk_status vk_options_set_sdf(vk_options *options, double band);
vk_status vk_options_set_udf(vk_options *options, double band);
/* Compression and half-precision floats of vk_grid_write_vdb_with (default blosc, full). */
vk_status vk_options_set_compression(vk_options *options, vk_compression compression);
vk_status vk_options_set_half(vk_options *options, int half);
/*
 * Any option by name: field `field` of request `request` (mesh, solid, subdiv, lines, limits,
 * write, or to_mesh's adaptivity: the tables of Python's voxelkit.OPTIONS) set to `value`, a JSON text such as
 * "2.5", "\"projective\"", "true", "null" or "[\"shell\"]". Checked and refused with the same
 * message as Python's keyword. The placement of mesh, solid, subdiv and lines (`resolution`,
 * `voxel_size`, `origin`, `bounds`) sets the grid every call shares: `resolution` as
 * vk_options_set_resolution does, `origin` "[0, 0, 0]" puts every voxel centre on a multiple
 * of the voxel size, `bounds` "[[x0, y0, z0], [x1, y1, z1]]" fits the grid to that box and
 * keeps only the voxels whose centres lie in it.
 */
vk_status vk_options_set(vk_options *options, const char *request, const char *field,
                         const char *value);

/* ---- voxelization ----------------------------------------------------------------------- */

/* A voxel surface of `mesh` by the surface method of `options`. */
vk_status vk_voxelize_mesh(const vk_mesh *mesh, const vk_options *options, vk_grid **out);

/* The polylines of `mesh` (or, without any, the edges of its faces) by dominant-axis
 * marching; vertex colours, when the file has them, go into the grid's colour channel. */
vk_status vk_voxelize_lines(const vk_mesh *mesh, const vk_options *options, vk_grid **out);

/* The limit surface of `mesh` taken as a Catmull-Clark control mesh (Lai & Cheng), with the
 * adjacency of vk_options_set_separability; normals always. */
vk_status vk_voxelize_subdivision(const vk_mesh *mesh, const vk_options *options,
                                  vk_grid **out);

/* The implicit surface `formula` = 0 inside the box bounds_min .. bounds_max by interval
 * octree (Stolte & Kaufman); the resolution of `options` spans the longest side. */
vk_status vk_voxelize_formula(const char *formula, vk_coordinates coordinates,
                              const double bounds_min[3], const double bounds_max[3],
                              const vk_options *options, vk_grid **out);

/* ---- solids, Booleans, measures --------------------------------------------------------- */

/* The solid of `mesh` (surface and inside voxels) by the fill method of `options`;
 * `measures` may be NULL. The flood's inside follows the solid request's `inside` (set by
 * vk_options_set(options, "solid", "inside", "\"parity\"")): by default the generalized
 * winding number, so open, overlapping and hollow meshes fill too; VK_ERROR_BAD_MESH where the
 * rule cannot apply (parity on an open mesh). Depth layers refuse voxels they cannot
 * classify. */
vk_status vk_fill_mesh(const vk_mesh *mesh, const vk_options *options, vk_grid **solid,
                       vk_measures *measures);

/* The solid of the closed limit surface of `mesh` taken as a Catmull-Clark control mesh
 * (Lai & Cheng): its voxels, as vk_voxelize_subdivision makes them, and the inside flooded
 * from seeds one voxel against the limit normals by FloodingXYZ (GRAYSTACK from
 * vk_options_set_flood when it asks for FloodingXYZ, else 2^20 entries); `measures` may be
 * NULL. An open control mesh is refused. */
vk_status vk_fill_subdivision(const vk_mesh *mesh, const vk_options *options, vk_grid **solid,
                              vk_measures *measures);

/* The inside of a closed voxel surface by exterior flooding, and its measures. */
vk_status vk_measure_surface(const vk_grid *surface, vk_measures *measures);

/* a op b on a's transform; b is resampled when `resample` is non-zero and the transforms
 * differ (an error otherwise). */
vk_status vk_grid_combine(const vk_grid *a, const vk_grid *b, vk_boolean op, int resample,
                          vk_grid **out);

/* ---- grids ------------------------------------------------------------------------------ */

/* Reads grid `name` of a .vdb file (NULL: the voxel set voxelkit writes, `voxels`, else
 * `density`, else the first Bool, Mask or Float grid) as the voxels it stands for: a level
 * set's inside (its negative values and tiles, active or not), any other grid's active
 * voxels. */
vk_status vk_grid_read_vdb(const char *path, const char *name, vk_grid **out);

/*
 * Writes every grid the CLI writes for the same job, with its metadata: `density` (a fog
 * volume, whole blocks as tiles), `normal` and `Cd` when the grid has them, a solid's
 * `shell` and `interior`, a level set as `surface` (LEVEL_SET class, its inside as inactive
 * -background tiles), unsigned distances as `distance` (written to a temporary file, then
 * renamed). A .nvdb path writes the same grids in NanoVDB's layout (uncompressed, names,
 * transforms and classes but no other metadata); a .binvox or .vox path the voxel set alone.
 */
vk_status vk_grid_write_vdb(const vk_grid *grid, const char *path);
/* vk_grid_write_vdb with the write options of `options`: the grids named (write.grids),
 * the compression and half precision. */
vk_status vk_grid_write_vdb_with(const vk_grid *grid, const char *path,
                                 const vk_options *options);

/*
 * The grid's surface as a closed, 2-manifold triangle mesh, counter-clockwise seen from
 * outside (world coordinates): a level set's zero set (vk_options_set_sdf), a solid's or a
 * voxel surface's boundary, half way between its voxels and empty ones. Read it with
 * vk_mesh_counts and vk_mesh_copy_triangles; free it with vk_mesh_free.
 */
vk_status vk_grid_to_mesh(const vk_grid *grid, vk_mesh **out);
/* The same mesh written to `path`: .obj, .ply, .stl or .glb by the extension (atomically). */
vk_status vk_grid_write_mesh(const vk_grid *grid, const char *path);
/* vk_grid_to_mesh and vk_grid_write_mesh with the flat regions merged as `options` say
 * (vk_options_set(options, "to_mesh", "adaptivity", "0.25"): every vertex within half that
 * many voxels of the plane of each triangle it replaces; options NULL: none merged). */
vk_status vk_grid_to_mesh_with(const vk_grid *grid, const vk_options *options, vk_mesh **out);
vk_status vk_grid_write_mesh_with(const vk_grid *grid, const char *path,
                                  const vk_options *options);

/*
 * The grids vk_grid_write_vdb_with(grid, path, options) writes (options NULL: those
 * vk_grid_write_vdb writes), as arrays to build one's own grids from (voxelkit/openvdb.hpp
 * builds OpenVDB grids of them): how many, each one described, and its arrays:
 * `leaf_origins` 3 * leaf_count int32, `masks` 8 * leaf_count uint64 (OpenVDB's mask words),
 * `values` every voxel's value of every leaf in OpenVDB's voxel order (512 * leaf_count floats,
 * 3 * 512 * leaf_count for VK_VALUE_VEC3S, none for VK_VALUE_BOOL; inactive voxels hold the
 * background, or minus it inside a level set), `tiles` 4 * tile_count int32 (origin, edge 8 or
 * 128), every tile holding `tile_value`, active when `tiles_active` (a level set's interior
 * tiles are not). Each call makes the grid asked for anew.
 */
typedef enum vk_value_type { VK_VALUE_BOOL = 0, VK_VALUE_FLOAT = 1, VK_VALUE_VEC3S = 2 } vk_value_type;
typedef enum vk_export_class {
    VK_CLASS_NONE = 0,
    VK_CLASS_FOG_VOLUME = 1,
    VK_CLASS_LEVEL_SET = 2
} vk_export_class;
typedef enum vk_vector_type {
    VK_VECTOR_NONE = 0,
    VK_VECTOR_COVARIANT_NORMALIZE = 1,
    VK_VECTOR_INVARIANT = 2
} vk_vector_type;
typedef struct vk_export_info {
    char name[256];
    int value_type;  /* vk_value_type */
    int grid_class;  /* vk_export_class */
    int vector_type; /* vk_vector_type */
    size_t leaf_count;
    size_t tile_count;
    float background;
    int tiles_active;
    float tile_value;
} vk_export_info;
vk_status vk_grid_export_count(const vk_grid *grid, const vk_options *options, size_t *count);
vk_status vk_grid_export_info(const vk_grid *grid, const vk_options *options, size_t index,
                              vk_export_info *info);
vk_status vk_grid_export_arrays(const vk_grid *grid, const vk_options *options, size_t index,
                                int32_t *leaf_origins, uint64_t *masks, float *values,
                                int32_t *tiles);

vk_status vk_grid_voxel_count(const vk_grid *grid, uint64_t *count);
vk_status vk_grid_leaf_count(const vk_grid *grid, size_t *count);
vk_status vk_grid_transform(const vk_grid *grid, double *voxel_size, double origin[3]);

/*
 * Copies leaves first .. first + count: `origins` receives 3 * count int32 (x, y, z, the
 * index of the leaf's voxel (0, 0, 0)), `masks` 8 * count uint64 (OpenVDB's mask words).
 * Leaves with coordinates beyond 32 bits are refused.
 */
vk_status vk_grid_copy_leaves(const vk_grid *grid, size_t first, size_t count,
                              int32_t *origins, uint64_t *masks);

/*
 * Whole 8^3 and 128^3 blocks are held as tiles, not leaves (a solid's inside is mostly
 * tiles): the voxel count is the leaves' voxels plus the tiles'. vk_grid_copy_tiles copies
 * tiles first .. first + count: `origins` receives 3 * count int32 (the tile's voxel
 * (0, 0, 0)), `edges` count int32 (8 or 128: OpenVDB's tiles of level 1 and 2, for
 * `tree.addTile(edge == 8 ? 1 : 2, origin, value, true)`). Tiles carry no normals or colours.
 */
vk_status vk_grid_tile_count(const vk_grid *grid, size_t *count);
vk_status vk_grid_copy_tiles(const vk_grid *grid, size_t first, size_t count, int32_t *origins,
                             int32_t *edges);

/*
 * Copies per-voxel normals or colours of leaves first .. first + count: 3 * 512 floats per
 * leaf in voxel order n (zeros where a voxel is off). VK_ERROR_INVALID_ARGUMENT when the
 * grid has no such channel.
 */
vk_status vk_grid_copy_normals(const vk_grid *grid, size_t first, size_t count, float *normals);
vk_status vk_grid_copy_colors(const vk_grid *grid, size_t first, size_t count, float *colors);

/*
 * Copies the coordinates of every active voxel, 3 int64 each, into `coords` (room for
 * `capacity` voxels). `written` receives the voxel count; when it exceeds `capacity` nothing
 * is copied and VK_ERROR_BUFFER_TOO_SMALL is returned.
 */
vk_status vk_grid_copy_voxels(const vk_grid *grid, int64_t *coords, size_t capacity,
                              size_t *written);

/*
 * The metadata items every grid of the job's .vdb file carries (`method`, `source_file`,
 * `resolution` or `voxel_size`, ..., `voxelkit_version`): their count, then item `index`: its
 * key, its type, its value as text (every type), and as a number in `integer` (VK_META_INT) or
 * `real` (VK_META_REAL). No pointer may be NULL; the strings live as long as the grid.
 */
typedef enum vk_meta_type {
    VK_META_TEXT = 0,
    VK_META_INT = 1,
    VK_META_REAL = 2
} vk_meta_type;
vk_status vk_grid_metadata_count(const vk_grid *grid, size_t *count);
vk_status vk_grid_metadata_item(const vk_grid *grid, size_t index, const char **key,
                                vk_meta_type *type, const char **text, int64_t *integer,
                                double *real);

/* What a grid holds: voxels (a surface or a solid), a level set (vk_options_set_sdf) or
 * unsigned distances (vk_options_set_udf); `background` receives the distance grids'
 * background, band x voxel size (0 for voxels). */
typedef enum vk_grid_class {
    VK_GRID_VOXELS = 0,
    VK_GRID_LEVEL_SET = 1,
    VK_GRID_UNSIGNED_DISTANCE = 2
} vk_grid_class;
vk_status vk_grid_get_class(const vk_grid *grid, vk_grid_class *grid_class, float *background);

/*
 * Copies the distances of leaves first .. first + count of a distance grid: 512 floats per
 * leaf in voxel order n, the distance (world units) at active voxels and what OpenVDB reads
 * at inactive ones: -background inside a level set, +background elsewhere (so that
 * openvdb::tools::signedFloodFill gives the tiles beyond the band their sign).
 * VK_ERROR_INVALID_ARGUMENT for a voxel grid.
 */
vk_status vk_grid_copy_values(const vk_grid *grid, size_t first, size_t count, float *values);

/*
 * A voxel grid from the caller's own leaves and tiles, in the layout vk_grid_copy_leaves and
 * vk_grid_copy_tiles give: `leaf_origins` 3 * leaf_count int32 (multiples of 8), `masks`
 * 8 * leaf_count uint64, `tile_origins` 3 * tile_count int32 and `tile_edges` tile_count
 * int32 (8 or 128, origins multiples of the edge); world = origin + voxel_size * index.
 * Leaves at the same origin are OR-ed. The grid enters vk_grid_combine, vk_measure_surface
 * and the writers as any other.
 */
vk_status vk_grid_from_leaves(double voxel_size, const double origin[3], size_t leaf_count,
                              const int32_t *leaf_origins, const uint64_t *masks,
                              size_t tile_count, const int32_t *tile_origins,
                              const int32_t *tile_edges, vk_grid **out);

vk_status vk_grid_free(vk_grid *grid);

/* Panics inside Rust on purpose and returns what the caller sees (VK_ERROR_INTERNAL): lets
 * bindings check their error path. */
vk_status vk_debug_panic(void);

#ifdef __cplusplus
}
#endif

#endif /* VOXELKIT_H */
