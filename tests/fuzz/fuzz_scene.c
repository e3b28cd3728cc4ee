/* fuzz_scene.c — libFuzzer harness for the scene parser: scene_load on arbitrary bytes must
 * return 0 or 2 with a one-line message, never crash, leak or hang. */
#include <stdlib.h>
#include <string.h>

#include "fuzz_input.h"
#include "scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* One input: loaded, checked for a one-line message, freed. */
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_input_file(data, size, ".json");
    if (!path) return 0;
    scene_texgen_enabled = 0; /* a "generate" is parsed, never run: counts up to 10^6 */
    Scene s;
    char err[1024] = "";
    int rc = scene_load(path, &s, err, sizeof err);
    if (rc == 0)
        scene_free(&s);
    else if (rc != 2 || !err[0] || strchr(err, '\n'))
        abort(); /* bad input must give status 2 and one line */
    return 0;
}
