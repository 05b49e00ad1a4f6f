"""The channel to seepd with the CLI's connection options: address (SEEP_SERVER), bearer token
(SEEP_TOKEN, or a token file), TLS with the system's roots or a given PEM CA."""
import os

import grpc

DEFAULT_SERVER = "127.0.0.1:50051"
# Fields of a big packing exceed gRPC's 4 MB default; the CLI allows the same.
MAX_RECEIVE_BYTES = 128 << 20


def read_token(token, token_file):
    """The bearer token: token_file's content (stripped) wins over token, which defaults to
    SEEP_TOKEN. Raises ValueError naming the option for an unusable one."""
    if token_file is not None:
        try:
            with open(token_file) as f:
                token = f.read().strip()
        except OSError as error:
            raise ValueError("token_file %s: cannot be read: %s" % (token_file, error)) from None
        if not token:
            raise ValueError("token_file %s: is empty" % token_file)
    elif token is None:
        token = os.environ.get("SEEP_TOKEN", "")
    if any(not 0x21 <= ord(c) <= 0x7e for c in token):
        raise ValueError("token: only visible ASCII characters are allowed (no spaces or "
                         "control characters)")
    return token


def read_ca(tls_ca):
    """The PEM bytes of the CA file, or ValueError naming it."""
    try:
        with open(tls_ca, "rb") as f:
            pem = f.read()
    except OSError as error:
        raise ValueError("tls_ca %s: cannot be read: %s" % (tls_ca, error)) from None
    if b"-----BEGIN" not in pem:
        raise ValueError("tls_ca %s: is not a PEM certificate" % tls_ca)
    return pem


def open_channel(server, tls, tls_ca):
    options = [("grpc.max_receive_message_length", MAX_RECEIVE_BYTES)]
    if not tls and tls_ca is None:
        return grpc.insecure_channel(server, options=options)
    roots = read_ca(tls_ca) if tls_ca is not None else None  # None: the system's roots
    return grpc.secure_channel(server, grpc.ssl_channel_credentials(roots), options=options)


def call_metadata(token):
    # Plain metadata rather than call credentials: gRPC sends call credentials over secure
    # channels only, and a token-protected seepd may be plaintext on loopback (as in the CLI).
    return (("authorization", "Bearer " + token),) if token else ()
