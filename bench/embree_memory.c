/* Embree 3's memory for a triangle mesh (OBJ), for pathlab's bytes per triangle to be compared
 * with: the mesh is read as ../shared/tools/embree-bench/embree_bench.c reads it and built as
 * it builds it (RTC_BUILD_QUALITY_HIGH, one triangle geometry), and a device memory monitor
 * counts what Embree holds once the scene is committed.
 *
 * Two builds: with the vertex and index buffers shared (the application's own arrays, which
 * Embree does not count), which gives the acceleration structure alone; and with buffers
 * Embree allocates (rtcSetNewGeometryBuffer, as embree_bench does), which gives everything
 * the traced scene holds. Prints one line of `key value` pairs.
 *
 * Build: cc -O2 -o embree_memory embree_memory.c -lembree3 */
#include <embree3/rtcore.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>

static float *V;
static unsigned *F;
static size_t nv, nf, cv, cf;

static void push_v(float x, float y, float z) {
  if (nv == cv) { cv = cv ? 2 * cv : 1024; V = realloc(V, cv * 12); }
  V[3 * nv] = x; V[3 * nv + 1] = y; V[3 * nv + 2] = z; nv++;
}

static void push_f(unsigned a, unsigned b, unsigned c) {
  if (nf == cf) { cf = cf ? 2 * cf : 1024; F = realloc(F, cf * 12); }
  F[3 * nf] = a; F[3 * nf + 1] = b; F[3 * nf + 2] = c; nf++;
}

/* Vertices and faces (fans for polygons, negative indices relative), as embree_bench reads them. */
static void load_obj(const char *path) {
  FILE *fp = fopen(path, "r");
  if (!fp) { perror(path); exit(1); }
  char line[4096];
  while (fgets(line, sizeof line, fp)) {
    if (line[0] == 'v' && line[1] == ' ') {
      float x, y, z;
      if (sscanf(line + 2, "%f %f %f", &x, &y, &z) == 3) push_v(x, y, z);
    } else if (line[0] == 'f' && line[1] == ' ') {
      int ids[64], n = 0;
      char *s = strtok(line + 2, " \t\r\n");
      while (s && n < 64) { int i = atoi(s); ids[n++] = i < 0 ? (int)nv + i : i - 1; s = strtok(NULL, " \t\r\n"); }
      for (int k = 1; k + 1 < n; k++) push_f(ids[0], ids[k], ids[k + 1]);
    }
  }
  fclose(fp);
}

/* Bytes Embree holds now, and the most it held. */
static ssize_t held, peak;

static bool monitor(void *user, ssize_t bytes, bool post) {
  (void)user;
  (void)post;
  held += bytes;
  if (held > peak) peak = held;
  return true;
}

/* Builds the scene; returns the bytes Embree holds once it is committed. */
static ssize_t build(RTCDevice dev, int shared) {
  held = peak = 0;
  RTCScene scene = rtcNewScene(dev);
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
  if (shared) {
    /* Embree reads a vertex with a 16-byte load, so a shared vertex buffer needs 4 bytes after
       its last vertex: one vertex more. */
    V = realloc(V, (nv + 1) * 12);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, V, 0, 12, nv);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, F, 0, 12, nf);
  } else {
    float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, nv);
    memcpy(vb, V, nv * 12);
    unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, nf);
    memcpy(ib, F, nf * 12);
  }
  rtcCommitGeometry(g);
  rtcAttachGeometry(scene, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(scene);
  ssize_t bytes = held;
  rtcReleaseScene(scene);
  return bytes;
}

int main(int argc, char **argv) {
  if (argc < 2) { fprintf(stderr, "usage: %s mesh.obj\n", argv[0]); return 2; }
  load_obj(argv[1]);
  if (nf == 0) { fprintf(stderr, "%s: no triangles\n", argv[1]); return 1; }
  RTCDevice dev = rtcNewDevice(NULL);
  rtcSetDeviceMemoryMonitorFunction(dev, monitor, NULL);
  ssize_t accel = build(dev, 1);
  ssize_t accel_peak = peak;
  ssize_t all = build(dev, 0);
  printf("triangles %zu vertices %zu accel_bytes %zd accel_peak_bytes %zd with_buffers_bytes %zd "
         "accel_bytes_per_triangle %.1f with_buffers_bytes_per_triangle %.1f\n",
         nf, nv, accel, accel_peak, all, (double)accel / nf, (double)all / nf);
  rtcReleaseDevice(dev);
  return 0;
}
