//! `schuler bag info FILE`: the topics of a ROS bag (ROS 1 `.bag`, or ROS 2 MCAP
//! file or rosbag2 directory, told by content) with their types, message counts, rates and log-time spans, and which
//! of them `schuler nav --bag` would read.

use anyhow::Result;
use schuler_io::bag::info::{scan, table};
use schuler_io::bag::input::Kind;
use std::path::PathBuf;

/// Arguments of `schuler bag`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// What to do with the bag.
    #[command(subcommand)]
    pub command: BagCommand,
}

/// The `bag` subcommands.
#[derive(clap::Subcommand, Debug)]
pub enum BagCommand {
    /// List the topics: type, messages, rate, first and last log time.
    Info {
        /// The bag: a ROS 1 .bag file, an .mcap file or a rosbag2 directory.
        #[arg(value_name = "BAG")]
        bag: PathBuf,
    },
}

/// `schuler bag`.
pub fn run(args: Args) -> Result<()> {
    match args.command {
        BagCommand::Info { bag } => {
            let topics = scan(&bag, |_| Ok(()))?;
            print!("{}", table(&bag, &topics));
            for kind in Kind::ALL {
                let of_type: Vec<&str> = topics
                    .iter()
                    .filter(|t| Kind::of_type(&t.topic.type_name) == Some(kind))
                    .map(|t| t.topic.name.as_str())
                    .collect();
                match of_type[..] {
                    [] => {}
                    [one] => println!("nav --bag reads {} from {one}", kind.type_name()),
                    _ => println!(
                        "nav --bag needs {} to choose among the {} topics {}",
                        kind.flag(),
                        kind.type_name(),
                        of_type.join(", ")
                    ),
                }
            }
            Ok(())
        }
    }
}
