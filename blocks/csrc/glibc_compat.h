/* Portable FMU binaries: the maths functions bound to the oldest glibc versions that
 * provide them. glibc 2.29 gave exp, log, pow, exp2 and log2 new symbol versions (faster,
 * same results within their error bounds), and 2.35 hypot; a binary linked against a newer
 * glibc asks for those, and a Linux with an older one (Debian 11, Ubuntu 20.04, RHEL 8)
 * refuses to load it. setup.py compiles the FMU binaries with this header forced in
 * (-include); the Python extensions, built for the machine they run on, do not need it. */
#ifndef BLOCKS_GLIBC_COMPAT_H
#define BLOCKS_GLIBC_COMPAT_H

#include <math.h> /* defines __GLIBC__ on glibc */

#if defined(__GLIBC__) && (defined(__x86_64__) || defined(__aarch64__))
#if defined(__x86_64__)
#define BLK_GLIBC_BASE "GLIBC_2.2.5"
#else
#define BLK_GLIBC_BASE "GLIBC_2.17"
#endif
__asm__(".symver exp,exp@" BLK_GLIBC_BASE);
__asm__(".symver log,log@" BLK_GLIBC_BASE);
__asm__(".symver pow,pow@" BLK_GLIBC_BASE);
__asm__(".symver exp2,exp2@" BLK_GLIBC_BASE);
__asm__(".symver log2,log2@" BLK_GLIBC_BASE);
__asm__(".symver hypot,hypot@" BLK_GLIBC_BASE);
__asm__(".symver fmod,fmod@" BLK_GLIBC_BASE);
#endif

#endif
