//! The run viewer behind `swarm view <run-dir>` and `swarm run --view`: a local web server whose page replays a
//! run directory (or follows one while the run writes it), drawn in the browser from the record files alone.
//!
//! The page and the routes are described in docs/viewer.md. Everything is read from the run directory on
//! demand (the trajectory is indexed by tick, never loaded whole), so the viewer works for runs of any length,
//! and a live run never waits for it.

pub mod animation;
pub mod events;
pub mod frames;
pub mod lines;
pub mod objects;
pub mod page;
pub mod parquet_trajectory;
pub mod run;
pub mod server;
pub mod supervisors;
pub mod trajectory;
pub mod trajectory_source;

use std::net::{IpAddr, SocketAddr, TcpListener};
use std::path::Path;

pub use run::RunRecord;

/// Why the viewer cannot start.
#[derive(Debug, thiserror::Error)]
pub enum ViewerError {
    /// The folder is not a run directory.
    #[error("{0}")]
    NotARun(String),
    /// The port is taken.
    #[error(
        "{address} is in use by another program: choose another port, or port 0 for any free one"
    )]
    PortInUse {
        /// The address asked for.
        address: SocketAddr,
    },
    /// Another socket error.
    #[error("cannot serve on {address}: {source}")]
    Socket {
        /// The address asked for.
        address: SocketAddr,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
}

/// A viewer being served by a thread of its own, for as long as the process lives.
pub struct Viewer {
    address: SocketAddr,
}

impl Viewer {
    /// Serves the run in `dir` on `bind:port` (port 0: any free port). `live`: the run is still being written.
    pub fn start(dir: &Path, live: bool, bind: IpAddr, port: u16) -> Result<Viewer, ViewerError> {
        let record = RunRecord::open(dir, live).map_err(ViewerError::NotARun)?;
        if !live {
            for problem in record.problems() {
                tracing::warn!("{problem}");
            }
        }
        let wanted = SocketAddr::new(bind, port);
        let listener = TcpListener::bind(wanted).map_err(|source| {
            if source.kind() == std::io::ErrorKind::AddrInUse {
                ViewerError::PortInUse { address: wanted }
            } else {
                ViewerError::Socket {
                    address: wanted,
                    source,
                }
            }
        })?;
        let socket_error = |source| ViewerError::Socket {
            address: wanted,
            source,
        };
        let address = listener.local_addr().map_err(socket_error)?;
        listener.set_nonblocking(true).map_err(socket_error)?;
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_io()
            .enable_time()
            .build()
            .map_err(socket_error)?;
        let shared = server::Shared::new(record, allowed_hosts(address));
        std::thread::Builder::new()
            .name("viewer".into())
            .spawn(move || {
                runtime.block_on(async move {
                    match tokio::net::TcpListener::from_std(listener) {
                        Ok(listener) => {
                            if let Err(e) = axum::serve(listener, server::routes(shared)).await {
                                tracing::error!("the viewer stopped serving: {e}");
                            }
                        }
                        Err(e) => tracing::error!("the viewer cannot serve on {address}: {e}"),
                    }
                })
            })
            .map_err(socket_error)?;
        Ok(Viewer { address })
    }

    /// The page's address.
    pub fn url(&self) -> String {
        format!("http://{}/", self.address)
    }
}

/// On a loopback address only requests naming this address (or `localhost`) are answered; on any other the
/// user chose to be reachable by other names too.
fn allowed_hosts(address: SocketAddr) -> Vec<String> {
    if !address.ip().is_loopback() {
        return Vec::new();
    }
    let port = address.port();
    vec![
        format!("{address}"),
        format!("localhost:{port}"),
        format!("127.0.0.1:{port}"),
        format!("[::1]:{port}"),
    ]
}
