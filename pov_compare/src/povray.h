/* povray.h -- write a scene as POV-Ray source and render it with the real
 * POV-Ray 3.7 (pov_compare).
 *
 * POV-Ray runs as a child process (fork/exec, no shell) in the output
 * directory, so that the scene's `#include "lens.inc"` and the relative
 * file names resolve there, with the settings that make it render exactly
 * one ray per pixel centre into linear 16-bit samples
 * (docs: shared notes povray.md section 5):
 *
 *   povray -D -V -GS -GR +I<scene.pov> +O<out.png> +W<w> +H<h> -A +Q9 -UA
 *          +FN16 File_Gamma=1.0 Dither=off +WT<threads>
 *
 * Its stdout and stderr are appended to a log file.  The PNG it writes is
 * read back with rs_png_read: 16-bit samples / 65535, linear, no gamma
 * decoding.  Nothing here prints; no global state. */
#ifndef PC_POVRAY_H
#define PC_POVRAY_H

#include <stddef.h>

#include "support/image.h"
#include "lensrender/scene.h"
#include "translate.h"

/* What went wrong in a render. */
typedef enum pc_povray_status {
    PC_POVRAY_OK = 0,
    PC_POVRAY_NOT_FOUND,   /* the executable could not be run (not on PATH) */
    PC_POVRAY_FAILED,      /* it ran and failed (non-zero exit, signal) */
    PC_POVRAY_NO_OUTPUT,   /* it succeeded but its PNG cannot be read */
    PC_POVRAY_SYSTEM       /* fork, pipe, log file, memory */
} pc_povray_status;

/* Look `program` up as execvp would: a name with a '/' is taken as a
 * path, otherwise each directory of $PATH is tried.  Writes the path
 * found into path (may be NULL).  Returns 1 when an executable file was
 * found, else 0. */
int pc_povray_find(const char *program, char *path, size_t path_size);

typedef struct pc_povray_job {
    const char *program;   /* "povray" or a path */
    const char *workdir;   /* povray's working directory */
    const char *pov_name;  /* the scene, relative to workdir */
    const char *png_name;  /* the output, relative to workdir */
    const char *log_path;  /* stdout and stderr appended here */
    int width, height;     /* >= 1 */
    int threads;           /* +WT; >= 1 */
} pc_povray_job;

/* Run POV-Ray on job and read its output into *out (overwritten; left
 * empty on failure).  *seconds gets the wall-clock time of the child
 * process (fork to exit).  On failure msg names the cause; for
 * PC_POVRAY_FAILED it quotes the last error line of the log. */
pc_povray_status pc_povray_render(const pc_povray_job *job, rs_image *out, double *seconds,
                                  char *msg, size_t msg_size);

/* Write the POV-Ray scene for scene (pc_translate with opts) to path.
 * Notes are appended to notes.  Returns 0, or -1 with a message. */
int pc_povray_write_scene(const rs_scene *scene, const pc_translate_opts *opts,
                          const char *path, pc_notes *notes, char *msg, size_t msg_size);

/* Copy the file from to the file to (replacing it).  Returns 0 or -1 with
 * a message. */
int pc_copy_file(const char *from, const char *to, char *msg, size_t msg_size);

/* The POV-Ray version from the banner in a log ("3.7.0.10.unofficial"),
 * or "" when none is found.  Returns 0 when found. */
int pc_povray_version_from_log(const char *log_path, char *version, size_t size);

#endif
