/* Test FMUs that misbehave inside one FMI call: they crash, abort, call exit, overflow the
 * stack or hang there, as FMUs from other tools sometimes do (misbehave.c).
 *
 * A model built with -DMISBEHAVE calls MISBEHAVE(call, t) first thing in each of its FMI
 * functions, with the function's name and the model's time (the step's start for
 * doStep). What happens is read at instantiation from the FMU's resources, the file
 * misbehave.txt, one line "CALL HOW [FROM_T] [READY]": in the FMI function CALL, once t
 * >= FROM_T (default 0), HOW is one of
 *     segv      a write through a null pointer (SIGSEGV)
 *     abort     abort() (SIGABRT)
 *     exit3     exit(3);  exit0: exit(0)
 *     overflow  unbounded recursion until the stack overflows (SIGSEGV)
 *     hang      never return (waiting for a signal); with READY, a path (a FIFO the test
 *               reads), "<pid> <parent pid>\n" is written there first
 * Without the file the FMU behaves. One library serves every case (the file differs), so
 * the tests compile it once.
 */
#ifndef MISBEHAVE_H
#define MISBEHAVE_H

#ifdef MISBEHAVE
void misbehave_read(const char *resources); /* fmiXInstantiate: the resource location (a URI or a path) */
void misbehave(const char *call, double t);
#define MISBEHAVE_SETUP(resources) misbehave_read(resources)
#define MISBEHAVE_AT(call, t) misbehave(call, t)
#else
#define MISBEHAVE_SETUP(resources) ((void)0)
#define MISBEHAVE_AT(call, t) ((void)0)
#endif

#endif
