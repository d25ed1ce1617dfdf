//! `pathlab view`: the arguments of [`pathlab_view::serve`] (a local web server that shows the
//! render converging, with the course's settings switchable live).

use crate::flags::SceneArgs;
use anyhow::Result;
use clap::Args;
use pathlab_view::{serve, ViewOptions};

/// Raw command-line arguments of `pathlab view`.
#[derive(Args, Debug)]
pub struct ViewArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Port to listen on (0: any free one).
    #[arg(long, default_value_t = 8184)]
    pub port: u16,
    /// Address to listen on. The default keeps the viewer to this machine; 0.0.0.0 exposes it
    /// to the network, deliberately.
    #[arg(long, default_value = "127.0.0.1")]
    pub host: String,
    /// Open the page in the default browser.
    #[arg(long)]
    pub open: bool,
}

/// Runs `pathlab view` until Ctrl-C.
pub fn run(args: &ViewArgs) -> Result<()> {
    let desc = args.scene.load()?;
    let signals = crate::farm::Signals::install();
    let options = ViewOptions {
        host: args.host.clone(),
        port: args.port,
        title: args.scene.name.clone(),
    };
    let open = args.open;
    serve(desc, &options, signals.cancel.clone(), |addr| {
        let url = format!("http://{addr}/");
        eprintln!("pathlab view: {url} (Ctrl-C stops the server)");
        if open {
            let opener = if cfg!(target_os = "macos") {
                "open"
            } else {
                "xdg-open"
            };
            if let Err(e) = std::process::Command::new(opener).arg(&url).spawn() {
                eprintln!("warning: cannot open a browser ({opener}: {e}); open {url} yourself");
            }
        }
    })
}
