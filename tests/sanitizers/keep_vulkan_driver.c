/* AddressSanitizer builds only (FGSR_SANITIZE contains address; linked into everything that links
 * the engine, and into the layer's test application): keeps Mesa's lavapipe driver loaded for the
 * whole process.
 *
 * Why: lavapipe allocates 128 bytes in a pthread_once initialisation during
 * vkEnumeratePhysicalDevices and keeps the pointer in its own globals. The Vulkan loader dlcloses
 * the driver at vkDestroyInstance, the globals go away with it, and LeakSanitizer reports the block
 * at exit ("Direct leak of 128 byte(s) ... in <unknown module>"), so fgsrd and fgsr exit 1. A
 * suppression cannot name it: by the time LeakSanitizer symbolises the stack the driver is
 * unmapped (module unknown, no function names; `leak:libvulkan_lvp.so` does not match), and the
 * frames that could be named (vkEnumeratePhysicalDevices) are only captured by the slow unwinder
 * (fast_unwind_on_malloc=0), which made a short `fgsr eval` about 8 times slower. A second,
 * RTLD_NODELETE reference makes the loader's dlclose leave the driver mapped: its globals stay
 * roots, the block is reachable, and any other leak keeps being reported with the driver's frames
 * named. docs/RELIABILITY.md, "Sanitizers and fuzzing". */
#include <dlfcn.h>

__attribute__((constructor)) static void fgsr_keep_vulkan_driver_loaded(void) {
    /* Without lavapipe installed there is nothing to keep (the handle is deliberately kept). */
    (void)dlopen("libvulkan_lvp.so", RTLD_LAZY | RTLD_LOCAL | RTLD_NODELETE);
}
