//! `pathlab view`: the arguments of [`pathlab_view::serve`] (a local web server that shows the
//! render converging, with the course's settings switchable live).

use anyhow::Result;
use clap::Args;
use pathlab_view::{serve, ViewOptions};

/// Raw command-line arguments of `pathlab view`.
#[derive(Args, Debug)]
pub struct ViewArgs {
    /// Scene file or built-in scene name.
    #[arg(default_value = "cornell-box")]
    pub scene: String,
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
    /// Image size WIDTH HEIGHT (default: the scene's).
    #[arg(short = 'r', long, num_args = 2, value_names = ["WIDTH", "HEIGHT"])]
    pub resolution: Option<Vec<u32>>,
    /// Scene parameter NAME=VALUE for `$name` references in Mitsuba XML files (repeatable).
    #[arg(short = 'D', long = "define", value_name = "NAME=VALUE")]
    pub define: Vec<String>,
}

/// Runs `pathlab view` until Ctrl-C.
pub fn run(args: &ViewArgs) -> Result<()> {
    let params = crate::render_cmd::parse_defines(&args.define)?;
    let mut desc = pathlab_scene::load_with(&args.scene, &params)?;
    for w in &desc.warnings {
        eprintln!("warning: {w}");
    }
    pathlab_lab::render::apply_resolution(&mut desc, crate::image_size(&args.resolution))?;
    let signals = crate::farm::Signals::install();
    let options = ViewOptions {
        host: args.host.clone(),
        port: args.port,
        title: args.scene.clone(),
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
