/* povray.c -- the .pov file and the POV-Ray child process (povray.h). */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "povray.h"
#include "support/cli.h"

#define ARG_MAX_LEN 64

static int is_executable(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode) && access(path, X_OK) == 0;
}

int pc_povray_find(const char *program, char *path, size_t path_size)
{
    char buf[PATH_MAX];

    if (!program || !*program)
        return 0;
    if (strchr(program, '/')) {
        if (!is_executable(program))
            return 0;
        if (path && path_size)
            snprintf(path, path_size, "%s", program);
        return 1;
    }
    const char *p = getenv("PATH");
    if (!p || !*p)
        p = "/usr/local/bin:/usr/bin:/bin";
    while (*p) {
        const char *colon = strchr(p, ':');
        size_t len = colon ? (size_t)(colon - p) : strlen(p);
        int n = len ? snprintf(buf, sizeof buf, "%.*s/%s", (int)len, p, program)
                    : snprintf(buf, sizeof buf, "./%s", program);
        if (n > 0 && (size_t)n < sizeof buf && is_executable(buf)) {
            if (path && path_size)
                snprintf(path, path_size, "%s", buf);
            return 1;
        }
        if (!colon)
            break;
        p = colon + 1;
    }
    return 0;
}

/* An absolute version of path (relative ones against the current
 * directory), so that it survives the child's chdir. */
static int absolute(const char *path, char *out, size_t size)
{
    char cwd[PATH_MAX];
    if (path[0] == '/')
        return snprintf(out, size, "%s", path) < (int)size ? 0 : -1;
    if (!getcwd(cwd, sizeof cwd))
        return -1;
    int n = snprintf(out, size, "%s/%s", cwd, path);
    return n > 0 && (size_t)n < size ? 0 : -1;
}

/* The first "Error" line of the log with its continuation lines (POV-Ray
 * wraps at 80 columns, continuing with a leading space), into out. */
static void error_from_log(const char *log_path, long from, char *out, size_t size)
{
    FILE *f = fopen(log_path, "r");
    char line[512];
    int found = 0;
    size_t used = 0;

    out[0] = '\0';
    if (!f)
        return;
    if (from > 0 && fseek(f, from, SEEK_SET) != 0) {
        fclose(f);
        return;
    }
    while (fgets(line, sizeof line, f)) {
        line[strcspn(line, "\r\n")] = '\0';
        if (found == 0 && (strstr(line, "Error") || strstr(line, "error"))) {
            found = 1; /* the first error is the most telling one */
            used = (size_t)snprintf(out, size, "%s", line);
        } else if (found == 1 && line[0] == ' ' && used + 1 < size) {
            used += (size_t)snprintf(out + used, size - used, "%s", line);
        } else if (found == 1) {
            break;
        }
        if (used >= size)
            used = size - 1;
    }
    fclose(f);
}

typedef struct child_report {
    int stage; /* 1 chdir, 2 exec */
    int err;
} child_report;

pc_povray_status pc_povray_render(const pc_povray_job *job, rs_image *out, double *seconds,
                                  char *msg, size_t msg_size)
{
    char exe[PATH_MAX], exe_abs[PATH_MAX];
    char a_in[PATH_MAX + 4], a_out[PATH_MAX + 4], a_w[ARG_MAX_LEN], a_h[ARG_MAX_LEN],
        a_wt[ARG_MAX_LEN];
    int pipefd[2], logfd;
    long log_start;
    pid_t pid;
    double t0;

    out->width = out->height = 0;
    out->rgb = NULL;
    *seconds = 0.0;
    if (!pc_povray_find(job->program, exe, sizeof exe)) {
        snprintf(msg, msg_size,
                 "POV-Ray not found: '%s' is not an executable %s (install it: "
                 "apt-get install -y povray, or pass --povray PATH)",
                 job->program, strchr(job->program, '/') ? "file" : "on PATH");
        return PC_POVRAY_NOT_FOUND;
    }
    if (absolute(exe, exe_abs, sizeof exe_abs) != 0) {
        snprintf(msg, msg_size, "%s: path too long", exe);
        return PC_POVRAY_SYSTEM;
    }
    snprintf(a_in, sizeof a_in, "+I%s", job->pov_name);
    snprintf(a_out, sizeof a_out, "+O%s", job->png_name);
    snprintf(a_w, sizeof a_w, "+W%d", job->width);
    snprintf(a_h, sizeof a_h, "+H%d", job->height);
    snprintf(a_wt, sizeof a_wt, "+WT%d", job->threads > 0 ? job->threads : 1);
    char *argv[] = {exe_abs, "-D", "-V", "-GS", "-GR", a_in, a_out, a_w, a_h, "-A", "+Q9",
                    "-UA", "+FN16", "File_Gamma=1.0", "Dither=off", a_wt, NULL};

    logfd = open(job->log_path, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (logfd < 0) {
        snprintf(msg, msg_size, "%s: cannot open: %s", job->log_path, strerror(errno));
        return PC_POVRAY_SYSTEM;
    }
    log_start = (long)lseek(logfd, 0, SEEK_END);
    {
        /* A header line in the log: the exact command. */
        char head[2 * PATH_MAX + 512];
        int n = snprintf(head, sizeof head, "==== pov_compare: (cd %s &&", job->workdir);
        for (size_t k = 0; argv[k] && n > 0 && (size_t)n < sizeof head; k++)
            n += snprintf(head + n, sizeof head - (size_t)n, " %s", argv[k]);
        if (n > 0 && (size_t)n < sizeof head - 3)
            n += snprintf(head + n, sizeof head - (size_t)n, ")\n");
        if (n > 0 && write(logfd, head, strlen(head)) < 0) {
            /* the log is a convenience; a failed header is not fatal */
        }
    }
    if (pipe(pipefd) != 0) {
        snprintf(msg, msg_size, "pipe: %s", strerror(errno));
        close(logfd);
        return PC_POVRAY_SYSTEM;
    }
    if (fcntl(pipefd[1], F_SETFD, FD_CLOEXEC) != 0 ||
        fcntl(pipefd[0], F_SETFD, FD_CLOEXEC) != 0) {
        snprintf(msg, msg_size, "fcntl: %s", strerror(errno));
        close(pipefd[0]);
        close(pipefd[1]);
        close(logfd);
        return PC_POVRAY_SYSTEM;
    }
    fflush(NULL);
    t0 = sp_now_seconds();
    pid = fork();
    if (pid < 0) {
        snprintf(msg, msg_size, "fork: %s", strerror(errno));
        close(pipefd[0]);
        close(pipefd[1]);
        close(logfd);
        return PC_POVRAY_SYSTEM;
    }
    if (pid == 0) {
        /* The child: only async-signal-safe calls from here on. */
        child_report rep = {0, 0};
        int nullfd = open("/dev/null", O_RDONLY);
        if (nullfd >= 0)
            dup2(nullfd, STDIN_FILENO);
        dup2(logfd, STDOUT_FILENO);
        dup2(logfd, STDERR_FILENO);
        if (chdir(job->workdir) != 0) {
            rep.stage = 1;
            rep.err = errno;
        } else {
            execv(exe_abs, argv);
            rep.stage = 2;
            rep.err = errno;
        }
        if (write(pipefd[1], &rep, sizeof rep) < 0) {
            /* nothing more can be done */
        }
        _exit(127);
    }
    close(pipefd[1]);
    close(logfd);
    child_report rep = {0, 0};
    ssize_t got;
    do
        got = read(pipefd[0], &rep, sizeof rep);
    while (got < 0 && errno == EINTR);
    close(pipefd[0]);
    int status = 0;
    pid_t w;
    do
        w = waitpid(pid, &status, 0);
    while (w < 0 && errno == EINTR);
    *seconds = sp_now_seconds() - t0;
    if (w < 0) {
        snprintf(msg, msg_size, "waitpid: %s", strerror(errno));
        return PC_POVRAY_SYSTEM;
    }
    if (got == (ssize_t)sizeof rep && rep.stage == 1) {
        snprintf(msg, msg_size, "%s: cannot enter directory: %s", job->workdir, strerror(rep.err));
        return PC_POVRAY_SYSTEM;
    }
    if (got == (ssize_t)sizeof rep && rep.stage == 2) {
        snprintf(msg, msg_size, "POV-Ray could not be run: %s: %s", exe_abs, strerror(rep.err));
        return PC_POVRAY_NOT_FOUND;
    }
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        char err[400];
        error_from_log(job->log_path, log_start, err, sizeof err);
        if (WIFSIGNALED(status))
            snprintf(msg, msg_size, "POV-Ray was killed by signal %d rendering %s (see %s)",
                     WTERMSIG(status), job->pov_name, job->log_path);
        else
            snprintf(msg, msg_size, "POV-Ray failed on %s (exit %d)%s%s (see %s)", job->pov_name,
                     WEXITSTATUS(status), err[0] ? ": " : "", err, job->log_path);
        return PC_POVRAY_FAILED;
    }

    char png[2 * PATH_MAX + 2], rmsg[512];
    int depth = 0;
    if (job->png_name[0] == '/')
        snprintf(png, sizeof png, "%s", job->png_name);
    else
        snprintf(png, sizeof png, "%s/%s", job->workdir, job->png_name);
    if (rs_png_read(png, out, &depth, rmsg, sizeof rmsg) != 0) {
        char err[400];
        error_from_log(job->log_path, log_start, err, sizeof err);
        /* POV-Ray 3.7 exits 0 after some fatal errors: quote the log. */
        snprintf(msg, msg_size, "POV-Ray wrote no readable image for %s%s%s (%s; see %s)",
                 job->pov_name, err[0] ? ": " : "", err, rmsg, job->log_path);
        return err[0] ? PC_POVRAY_FAILED : PC_POVRAY_NO_OUTPUT;
    }
    if (out->width != job->width || out->height != job->height || depth != 16) {
        snprintf(msg, msg_size, "%s: POV-Ray wrote %d x %d at %d bits, expected %d x %d at 16",
                 png, out->width, out->height, depth, job->width, job->height);
        rs_image_free(out);
        return PC_POVRAY_NO_OUTPUT;
    }
    return PC_POVRAY_OK;
}

int pc_povray_write_scene(const rs_scene *scene, const pc_translate_opts *opts,
                          const char *path, pc_notes *notes, char *msg, size_t msg_size)
{
    char tmsg[512] = "";
    FILE *f = fopen(path, "w");
    if (!f) {
        snprintf(msg, msg_size, "%s: cannot write: %s", path, strerror(errno));
        return -1;
    }
    int rc = pc_translate(scene, opts, f, notes, tmsg, sizeof tmsg);
    int werr = ferror(f);
    if (fclose(f) != 0)
        werr = 1;
    if (rc != 0) {
        snprintf(msg, msg_size, "%s: translation failed: %s", path, tmsg);
        return -1;
    }
    if (werr) {
        snprintf(msg, msg_size, "%s: write error", path);
        return -1;
    }
    return 0;
}

int pc_copy_file(const char *from, const char *to, char *msg, size_t msg_size)
{
    char buf[8192];
    size_t n;
    FILE *in = fopen(from, "rb");
    if (!in) {
        snprintf(msg, msg_size, "%s: cannot read: %s", from, strerror(errno));
        return -1;
    }
    FILE *out = fopen(to, "wb");
    if (!out) {
        snprintf(msg, msg_size, "%s: cannot write: %s", to, strerror(errno));
        fclose(in);
        return -1;
    }
    int bad = 0;
    while ((n = fread(buf, 1, sizeof buf, in)) > 0)
        if (fwrite(buf, 1, n, out) != n) {
            bad = 1;
            break;
        }
    if (ferror(in))
        bad = 1;
    fclose(in);
    if (fclose(out) != 0)
        bad = 1;
    if (bad) {
        snprintf(msg, msg_size, "copying %s to %s failed", from, to);
        return -1;
    }
    return 0;
}

int pc_povray_version_from_log(const char *log_path, char *version, size_t size)
{
    static const char key[] = "Ray Tracer Version ";
    char line[512];
    FILE *f = fopen(log_path, "r");
    version[0] = '\0';
    if (!f)
        return -1;
    while (fgets(line, sizeof line, f)) {
        char *p = strstr(line, key);
        if (!p)
            continue;
        p += sizeof key - 1;
        size_t n = strcspn(p, " \t\r\n");
        snprintf(version, size, "%.*s", (int)n, p);
        break;
    }
    fclose(f);
    return version[0] ? 0 : -1;
}
