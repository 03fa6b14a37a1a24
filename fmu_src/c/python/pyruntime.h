/* The Python runtime shared by the Python FMUs' loaders (loader.c, loader3.c); see pyruntime.c. */
#ifndef LCV_PYRUNTIME_H
#define LCV_PYRUNTIME_H

#include <stddef.h>

/* Once per process: find or start the Python, add the site-packages, import numpy and load
   the export library (LOADER_EXPORT_LIB) next to this binary.  Returns its handle, or NULL with
   *error the reason (for the host's log); *path is the library's path. */
void *pyrt_start(const char **error, const char **path);

/* count live instances; at the last free the resources folder goes off sys.path again */
void pyrt_instance_added(void);
void pyrt_instance_freed(const char *folder);

/* pythonfmu and pythonfmu3 turn "%20" into a space and cut "file://" out of the resources path;
   a folder whose path holds either is given to them as ``alias``, a symlink to it in a private
   folder under /tmp (made by pyrt_resource_alias, removed with its sys.path entries by
   pyrt_resource_alias_free) */
int pyrt_needs_alias(const char *folder);
int pyrt_resource_alias(const char *folder, char *alias, size_t size, char *why, size_t wsize);
void pyrt_resource_alias_free(const char *alias);

int pyrt_is_dir(const char *path);
int pyrt_is_file(const char *path);
int pyrt_valid_utf8(const unsigned char *s);

#endif
