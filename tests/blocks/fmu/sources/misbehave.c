/* The misbehaviours of misbehave.h. */
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "misbehave.h"

static char call_[64], how_[16], ready_[4096];
static double from_ = 0.0;

void misbehave_read(const char *resources)
{
    if (resources == NULL)
        return;
    if (strncmp(resources, "file://", 7) == 0)
        resources += 7;
    char path[4096];
    snprintf(path, sizeof path, "%s%smisbehave.txt", resources,
             resources[0] && resources[strlen(resources) - 1] == '/' ? "" : "/");
    FILE *f = fopen(path, "r");
    if (f == NULL)
        return;
    char line[4200];
    if (fgets(line, sizeof line, f) != NULL) {
        int n = sscanf(line, "%63s %15s %lf %4095s", call_, how_, &from_, ready_);
        if (n < 2)
            call_[0] = how_[0] = '\0';
        if (n < 3)
            from_ = 0.0;
    }
    fclose(f);
}

static int deeper(int n)
{
    volatile char pad[4096];
    pad[0] = (char)n;
    return deeper(n + 1) + pad[0];
}

void misbehave(const char *call, double t)
{
    if (strcmp(call, call_) != 0 || t < from_)
        return;
    if (strcmp(how_, "segv") == 0)
        *(volatile int *)0 = 1;
    else if (strcmp(how_, "abort") == 0)
        abort();
    else if (strcmp(how_, "exit3") == 0)
        exit(3);
    else if (strcmp(how_, "exit0") == 0)
        exit(0);
    else if (strcmp(how_, "overflow") == 0)
        deeper(0);
    else if (strcmp(how_, "hang") == 0) {
        if (ready_[0]) {
            int fd = open(ready_, O_WRONLY);
            if (fd >= 0) {
                char text[64];
                int n = snprintf(text, sizeof text, "%d %d\n", (int)getpid(), (int)getppid());
                if (write(fd, text, (size_t)n) < 0)
                    perror("misbehave: ready");
                close(fd);
            }
        }
        for (;;)
            pause();
    }
}
