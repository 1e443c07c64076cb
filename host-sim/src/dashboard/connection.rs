//! One client connection with a deadline: a connection on which nothing
//! moves, in either direction, for the idle time is closed (a request body
//! that stops coming, a client that stops reading, a kept-alive connection
//! nobody uses). The event stream writes four times a second, so an open
//! page is never idle. The time to send a request's headers is bounded
//! separately (hyper's header read timeout, `server::HEADER_TIMEOUT`).

use std::future::Future;
use std::io;
use std::pin::Pin;
use std::task::{Context, Poll};
use std::time::Duration;

use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};
use tokio::time::{sleep, Instant, Sleep};

/// A stream closed after `idle` without a byte read or written.
pub struct IdleLimited<S> {
    inner: S,
    idle: Duration,
    deadline: Pin<Box<Sleep>>,
}

impl<S> IdleLimited<S> {
    pub fn new(inner: S, idle: Duration) -> Self {
        Self {
            inner,
            idle,
            deadline: Box::pin(sleep(idle)),
        }
    }

    fn moved(&mut self) {
        self.deadline.as_mut().reset(Instant::now() + self.idle);
    }

    /// After the inner stream said "not yet": an error once the deadline
    /// has passed (the caller is woken when it does).
    fn waiting<T>(&mut self, cx: &mut Context<'_>) -> Poll<io::Result<T>> {
        match self.deadline.as_mut().poll(cx) {
            Poll::Ready(()) => Poll::Ready(Err(io::Error::new(
                io::ErrorKind::TimedOut,
                "the connection was idle too long",
            ))),
            Poll::Pending => Poll::Pending,
        }
    }
}

impl<S: AsyncRead + Unpin> AsyncRead for IdleLimited<S> {
    fn poll_read(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &mut ReadBuf<'_>,
    ) -> Poll<io::Result<()>> {
        let before = buf.filled().len();
        match Pin::new(&mut self.inner).poll_read(cx, buf) {
            Poll::Ready(Ok(())) => {
                if buf.filled().len() > before {
                    self.moved();
                }
                Poll::Ready(Ok(()))
            }
            Poll::Ready(Err(e)) => Poll::Ready(Err(e)),
            Poll::Pending => self.waiting(cx),
        }
    }
}

impl<S: AsyncWrite + Unpin> AsyncWrite for IdleLimited<S> {
    fn poll_write(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        data: &[u8],
    ) -> Poll<io::Result<usize>> {
        match Pin::new(&mut self.inner).poll_write(cx, data) {
            Poll::Ready(Ok(n)) => {
                if n > 0 {
                    self.moved();
                }
                Poll::Ready(Ok(n))
            }
            Poll::Ready(Err(e)) => Poll::Ready(Err(e)),
            Poll::Pending => self.waiting(cx),
        }
    }

    fn poll_flush(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        match Pin::new(&mut self.inner).poll_flush(cx) {
            Poll::Pending => self.waiting(cx),
            done => done,
        }
    }

    fn poll_shutdown(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.inner).poll_shutdown(cx)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    /// Reads what is there (waiting for it): the count, or the error.
    async fn read_some<S: AsyncRead + Unpin>(stream: &mut S) -> io::Result<usize> {
        let mut buf = [0u8; 8];
        std::future::poll_fn(|cx| {
            let mut read = ReadBuf::new(&mut buf);
            Pin::new(&mut *stream)
                .poll_read(cx, &mut read)
                .map_ok(|()| read.filled().len())
        })
        .await
    }

    #[test]
    fn a_silent_peer_is_cut_off_and_a_talking_one_is_not() {
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .unwrap();
        runtime.block_on(async {
            let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
            let mut far = std::net::TcpStream::connect(listener.local_addr().unwrap()).unwrap();
            let (near, _) = listener.accept().await.unwrap();
            let mut limited = IdleLimited::new(near, Duration::from_millis(300));
            // Bytes every 200 ms keep it open past its 300 ms.
            for _ in 0..3 {
                tokio::time::sleep(Duration::from_millis(200)).await;
                far.write_all(b"x").unwrap();
                assert_eq!(read_some(&mut limited).await.unwrap(), 1);
            }
            let started = Instant::now();
            let err = read_some(&mut limited).await.unwrap_err();
            assert_eq!(err.kind(), io::ErrorKind::TimedOut);
            // Not before its time; the upper bound only catches a hang.
            let waited = started.elapsed();
            assert!(
                waited >= Duration::from_millis(300) && waited < Duration::from_secs(5),
                "{waited:?}"
            );
        });
    }
}
