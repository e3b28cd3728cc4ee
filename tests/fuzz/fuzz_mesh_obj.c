/* fuzz_mesh_obj.c — libFuzzer harness for the OBJ reader: mesh_load on arbitrary bytes must
 * return 0 or -1 with a one-line message, never crash, leak or hang; a loaded mesh is also
 * given to the closed-mesh check. */
#include <stdlib.h>
#include <string.h>

#include "fuzz_input.h"
#include "mesh.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* One input: loaded, checked, freed. */
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_input_file(data, size, ".obj");
    if (!path) return 0;
    Mesh m;
    mesh_init(&m);
    char err[1024] = "";
    if (mesh_load(path, &m, err, sizeof err) == 0) {
        for (uint32_t i = 0; i < 3 * m.ntris; i++)
            if (m.tris[i] >= m.nverts) abort(); /* every index must be in range */
        char cerr[512];
        (void)mesh_check_closed(&m, cerr, sizeof cerr);
    } else if (!err[0] || strchr(err, '\n')) {
        abort(); /* a refused file must say why, on one line */
    }
    mesh_free(&m);
    return 0;
}
