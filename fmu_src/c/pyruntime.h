/* The Python runtime shared by the Python FMUs' loaders (loader.c, loader3.c); see pyruntime.c. */
#ifndef LCV_PYRUNTIME_H
#define LCV_PYRUNTIME_H

/* Once per process: find or start the Python, add the site-packages, import numpy and load
   the export library (LOADER_EXPORT_LIB) next to this binary.  Returns its handle, or NULL with
   *error the reason (for the host's log); *path is the library's path. */
void *pyrt_start(const char **error, const char **path);

/* count live instances; at the last free the resources folder goes off sys.path again */
void pyrt_instance_added(void);
void pyrt_instance_freed(const char *folder);

int pyrt_is_dir(const char *path);
int pyrt_is_file(const char *path);
int pyrt_valid_utf8(const unsigned char *s);

#endif
