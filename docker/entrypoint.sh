#!/bin/sh
# asymslide-entrypoint: the Docker image's ENTRYPOINT. Prepares the atlas directory and numba's cache for the
# user the server runs as, then execs the command (CMD: asymslide serve) as that user, never as root.
#
# Started as root (the image's default):
#   - the atlas directory ($ASYMSLIDE_ATLAS_DIR, /atlases) is created if missing;
#   - a directory owned by root (what `docker run -v DIR:/atlases` makes of a DIR that did not exist) is given
#     to the app user (uid 10001), and the command runs as that user;
#   - a directory owned by another user (a host user's folder) is left as it is, and the command runs as its
#     owner, so that the atlases written there stay that user's files;
#   - privileges are dropped with setpriv (util-linux) before anything else runs.
# Started as another user (docker run --user UID, Kubernetes runAsUser): nothing is changed; a directory that
# user cannot write is reported (the app still opens the atlases there, it cannot compute the default one).
# Either way numba's precompiled cache is used: numba only uses a cache directory it can write, so a user who
# cannot write the image's copy (any uid but 10001) gets a private copy under /tmp (a few MB, well under 1 s).
set -eu

APP_UID=10001
APP_GID=10001
ATLASES="${ASYMSLIDE_ATLAS_DIR:-/atlases}"

say() {
    echo "asymslide-entrypoint: $*" >&2
}

if [ "$(id -u)" = 0 ]; then
    mkdir -p "$ATLASES" 2>/dev/null || true
    run_uid=$APP_UID
    run_gid=$APP_GID
    if [ -d "$ATLASES" ]; then
        owner=$(stat -c %u "$ATLASES")
        if [ "$owner" = 0 ]; then
            if chown "$APP_UID:$APP_GID" "$ATLASES" 2>/dev/null; then
                say "$ATLASES belonged to root: given to the app user (uid $APP_UID), who writes the atlases there"
            fi
        elif [ "$owner" != "$APP_UID" ]; then
            run_uid=$owner
            run_gid=$(stat -c %g "$ATLASES")
            say "$ATLASES belongs to uid $run_uid: serving as uid $run_uid:$run_gid, so the atlases written there" \
                "stay that user's"
        fi
    fi
    # HOME: the app user's, or none that is writable for another uid (set below)
    if [ "$run_uid" = "$APP_UID" ]; then HOME=/home/asymslide; else HOME=/; fi
    export HOME
    exec setpriv --reuid="$run_uid" --regid="$run_gid" --clear-groups --no-new-privs -- "$0" "$@"
fi

# from here on: the user the command runs as
uid=$(id -u)
if [ ! -d "$ATLASES" ]; then
    say "WARNING: the atlas directory $ATLASES does not exist and cannot be created by uid $uid: the Atlas tab" \
        "has no atlases and cannot compute the default one. Mount a folder there: -v \"\$PWD/atlases:$ATLASES\""
elif [ ! -w "$ATLASES" ] || [ ! -x "$ATLASES" ]; then
    say "WARNING: the atlas directory $ATLASES (owner uid $(stat -c %u "$ATLASES"), mode $(stat -c %a "$ATLASES"))" \
        "is not writable by uid $uid: the Atlas tab opens the atlases there but cannot compute the default" \
        "atlas. Make it writable for uid $uid (e.g. on the host: chown $uid DIR), mount it without :ro, or start" \
        "the container without --user so that this entrypoint can hand the folder over."
fi

if [ -n "${NUMBA_CACHE_DIR:-}" ] && [ -d "$NUMBA_CACHE_DIR" ] && [ ! -w "$NUMBA_CACHE_DIR" ]; then
    copy="${TMPDIR:-/tmp}/asymslide-numba-cache-$uid"
    mkdir -p "$copy"
    cp -R "$NUMBA_CACHE_DIR/." "$copy/"
    NUMBA_CACHE_DIR=$copy
    export NUMBA_CACHE_DIR
fi

if [ ! -w "${HOME:-/}" ]; then
    HOME=$(mktemp -d "${TMPDIR:-/tmp}/asymslide-home-$uid.XXXXXX")
    export HOME
fi

exec "$@"
