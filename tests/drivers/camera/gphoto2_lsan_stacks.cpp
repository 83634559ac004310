// Linked into the test programs that reach libgphoto2's USB port library on a host with no USB devices at all (CI
// machines, containers). There libgphoto2 2.5.30's usb1 iolib leaks the empty device list and a zero-sized calloc on
// every lookup (tests/lsan.supp says why). The iolib is built without frame pointers and unloaded before the leak
// check, so with the sanitizers' fast unwinder those stacks end in "<unknown module>" and no suppression can name
// them; the slow unwinder reaches the libgphoto2_port function that the suppression names. Only these two small
// programs pay for it; a build without AddressSanitizer never calls this.
extern "C" const char* __asan_default_options() { return "fast_unwind_on_malloc=0"; }
