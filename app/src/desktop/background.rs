//! Work a panel runs on a thread of its own while the window keeps
//! drawing (a remesh preview, a scan fit): the thread asks for a frame when
//! it is done, and the panel takes the answer on the next one.

use std::sync::mpsc::{Receiver, TryRecvError, sync_channel};

use eframe::egui;

/// Work under way on its own thread, or its answer.
#[derive(Debug)]
pub enum Background<V, E> {
    /// Still working.
    Running {
        receive: Receiver<Result<V, E>>,
        /// What the work is ("the remesher"), for the message when its
        /// thread ends without an answer.
        what: &'static str,
        /// Makes an error of that message.
        failed: fn(String) -> E,
    },
    /// The answer.
    Done(Result<V, E>),
}

impl<V: Send + 'static, E: Send + 'static> Background<V, E> {
    /// Starts `work` on a thread named `thread`; `what` names the work in
    /// the messages `failed` makes when no thread can start or it ends
    /// without an answer.
    pub fn start(
        thread: &str,
        what: &'static str,
        failed: fn(String) -> E,
        ctx: &egui::Context,
        work: impl FnOnce() -> Result<V, E> + Send + 'static,
    ) -> Self {
        let (send, receive) = sync_channel(1);
        let ctx = ctx.clone();
        let spawned = std::thread::Builder::new()
            .name(thread.into())
            .spawn(move || {
                let _ = send.send(work());
                ctx.request_repaint();
            });
        match spawned {
            Ok(_) => Background::Running {
                receive,
                what,
                failed,
            },
            Err(e) => Background::Done(Err(failed(format!("cannot start {what}: {e}")))),
        }
    }

    /// Takes the answer if it has come.
    pub fn poll(&mut self) {
        if let Background::Running {
            receive,
            what,
            failed,
        } = self
        {
            match receive.try_recv() {
                Ok(answer) => *self = Background::Done(answer),
                Err(TryRecvError::Empty) => {}
                Err(TryRecvError::Disconnected) => {
                    *self = Background::Done(Err(failed(format!("{what} stopped"))));
                }
            }
        }
    }

    /// The answer; `None` while the work is under way.
    pub fn answer(&self) -> Option<&Result<V, E>> {
        match self {
            Background::Done(answer) => Some(answer),
            Background::Running { .. } => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wait(mut work: Background<u32, String>) -> Result<u32, String> {
        for _ in 0..1000 {
            work.poll();
            if let Background::Done(answer) = work {
                return answer;
            }
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        panic!("no answer in 5 s");
    }

    #[test]
    fn the_answer_comes_from_the_thread_and_a_thread_that_dies_says_so() {
        let ctx = egui::Context::default();
        let done = Background::start("test-work", "the adder", |m| m, &ctx, || Ok(2 + 2));
        assert_eq!(wait(done), Ok(4));
        let dies = Background::start(
            "test-work",
            "the adder",
            |m| m,
            &ctx,
            || panic!("the work fails (expected in this test)"),
        );
        assert_eq!(wait(dies), Err("the adder stopped".to_string()));
    }
}
